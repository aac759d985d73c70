// The colour step at the outline's ends along the path (src/vision/internal/path_end_steps.hpp),
// the evidence by which the tracker tells a body between the rods from the empty gap. Truth: the
// sphere ray-cast by ray_cast_ball_support.hpp in front of a table and two dark rods drawn along
// the path, so that the step at each end is the drawn colours' difference, |body − table| in
// linear RGB, and 0 where no body is drawn.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "internal/linear_light.hpp"
#include "internal/path_end_steps.hpp"
#include "outline_geometry_support.hpp"
#include "ray_cast_ball_support.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kRadius = 0.0127;  // m: a 1-inch ball, about 19 px across its radius here
constexpr double kX = 0.41, kZ = 0.105;
const Vector3d kBody(0.6, 0.2, 0.1), kTable(0.5, 0.45, 0.4), kRod(0.08, 0.06, 0.05);

struct Scene {
  OutlineGeometry geometry = TestOutlineGeometry(kRadius);
  cv::Mat occluder = cv::Mat::zeros(geometry.cal.camera.height, geometry.cal.camera.width, CV_8U);
  Vector2d centre_px, tangent_px;
  double radius_px = 0;

  Scene() {
    geometry.occluder = &occluder;
    centre_px = geometry.Project(kX, kZ);
    tangent_px = (geometry.Project(kX + 0.001, kZ) - centre_px).normalized();
    radius_px = (geometry.Project(kX, kZ + kRadius) - centre_px).norm();
  }

  // The table with a rod along the path on each side of the centre line, their edges 0.85 and
  // 1.3 radii from it: near the outline's top and bottom, as the rods meet a body between them.
  cv::Mat Draw(bool with_body) const {
    const Vector2d normal(-tangent_px.y(), tangent_px.x());
    auto back = [&](int u, int v) {
      const double off = std::abs((Vector2d(u, v) - centre_px).dot(normal));
      return off > 0.85 * radius_px && off < 1.3 * radius_px ? kRod : kTable;
    };
    return DrawBallOver(geometry, kRadius, kX, kZ, with_body ? &kBody : nullptr, back);
  }

  PathEndSteps Measure(const FrameView& view) const {
    return MeasurePathEndSteps(geometry, view, LinearTable(Transfer::kSrgb), kX, kZ, tangent_px, Vector2d::Zero());
  }
};

TEST(PathEndSteps, MeasureTheBodysStepAtBothEnds) {
  const Scene scene;
  const cv::Mat frame = scene.Draw(true);
  const PathEndSteps s = scene.Measure({frame, {0, 0}, 1});
  const double drawn = (kBody - kTable).norm();
  EXPECT_NEAR(s.leading, drawn, 0.004);  // 8-bit sRGB codes: a few thousandths in linear light
  EXPECT_NEAR(s.trailing, drawn, 0.004);
}

TEST(PathEndSteps, FindNoStepWhereTheGapIsEmpty) {
  const Scene scene;
  const cv::Mat frame = scene.Draw(false);
  const PathEndSteps s = scene.Measure({frame, {0, 0}, 1});
  EXPECT_GE(s.leading, 0);
  EXPECT_LT(s.leading, 0.004);
  EXPECT_GE(s.trailing, 0);
  EXPECT_LT(s.trailing, 0.004);
}

// A window of the frame (as the tracker keeps for its refits) that ends before the trailing end,
// and the near rail's band over the leading end: neither end is seen, and neither is judged.
TEST(PathEndSteps, SayNothingOfAnEndTheyCannotSee) {
  Scene scene;
  const cv::Mat frame = scene.Draw(true);
  const Vector2d c = scene.centre_px;
  const int left = static_cast<int>(c.x() - 0.6 * scene.radius_px), top = static_cast<int>(c.y() - 40);
  const cv::Rect window(left, top, frame.cols - left, 80);
  const PathEndSteps cut = scene.Measure({frame(window).clone(), window.tl(), 1});
  EXPECT_EQ(cut.trailing, -1);
  EXPECT_NEAR(cut.leading, (kBody - kTable).norm(), 0.004);

  const Vector2d lead = c + scene.radius_px * scene.tangent_px;
  cv::circle(scene.occluder, cv::Point(static_cast<int>(lead.x()), static_cast<int>(lead.y())), 12, cv::Scalar(1), cv::FILLED);
  const PathEndSteps hidden = scene.Measure({frame, {0, 0}, 1});
  EXPECT_EQ(hidden.leading, -1);
  EXPECT_NEAR(hidden.trailing, (kBody - kTable).norm(), 0.004);
}

}  // namespace
}  // namespace uphill::internal
