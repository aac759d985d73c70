// The lab's marks drawn by the synthetic clip (footage/synthetic_clip.hpp, ClipApparatus): the
// tape on the rods, the crossbar's feet, the ruler; and ClipRenderer::Sees, which tools/make_video
// uses to list only the apparatus points a person sees (the browser test clicks those alone).
// Truth: the geometry of the default view (DefaultClipSetup: the camera on the near side, y < 0,
// looking across at the apparatus) and the paints' definitions (black tape against steel rods), not
// the renderer's output compared with itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "footage/synthetic_clip.hpp"
#include "vision/apparatus_points.hpp"

namespace uphill {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

ClipSetup MarkedSetup() {
  ClipSetup setup = DefaultClipSetup(640, 360);
  setup.apparatus.tape_marks_x = {0.3, 0.6, 0.9};
  setup.apparatus.feet = setup.apparatus.ruler = true;
  return setup;
}

double Grey(const cv::Mat& linear, const Vector2d& pixel) {
  const cv::Vec3f c = linear.at<cv::Vec3f>(static_cast<int>(std::lround(pixel.y())), static_cast<int>(std::lround(pixel.x())));
  return (c[0] + c[1] + c[2]) / 3;
}

TEST(FootageLabMarks, EachTapeMarkIsBlackWhereTheBareRodBesideItIsSteel) {
  const ClipSetup setup = MarkedSetup();
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const cv::Mat picture = renderer.RenderLinear({});
  const Rails& rails = setup.scene.rails();
  for (double x : setup.apparatus.tape_marks_x)
    for (double side : {-1.0, 1.0}) {
      auto pixel_at = [&](double t) {
        return ProjectApparatusPoint(setup.calibration.camera, setup.calibration.pose,
                                     Vector3d(t, side * t * rails.tan_half_alpha, t * rails.tan_theta));
      };
      // The tape's paint is 0.035 of white and the steel's 0.5, both under the same light.
      EXPECT_LT(Grey(picture, pixel_at(x)), 0.1) << "tape at " << x << " m, side " << side;
      EXPECT_GT(Grey(picture, pixel_at(x + 0.02)), 0.2) << "bare rod 20 mm beyond " << x << " m, side " << side;
    }
}

TEST(FootageLabMarks, EveryApparatusPointIsSeenUnlessSomethingStandsInFrontOfIt) {
  const ClipSetup setup = MarkedSetup();
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const double reach =
      std::max({setup.scene.rod_radius(), setup.apparatus.min_rod_radius, setup.apparatus.foot_radius}) + 0.002;
  const std::vector<ApparatusPoint> points = ApparatusCalibrationPoints(
      setup.scene.rails(), setup.apparatus.crossbar_x, setup.apparatus.table_z, setup.apparatus.tape_marks_x);
  ASSERT_EQ(points.size(), 11u);
  // Without the body each is seen on its rod, tape or foot.
  for (const ApparatusPoint& p : points) EXPECT_TRUE(renderer.Sees(p.position, {}, reach)) << p.name;
  // The body sitting over the 300 mm marks: the camera is on the near side (y < 0), so the ball
  // stands in front of the far (+y) rail's mark and behind the near one's.
  const Vector2d over_mark(0.3, setup.scene.At(0.3).z);
  const Vector3d far_mark = points[5].position, near_mark = points[6].position;
  ASSERT_EQ(points[5].name, "mark 300 left");
  ASSERT_EQ(points[6].name, "mark 300 right");
  EXPECT_FALSE(renderer.Sees(far_mark, {over_mark}, reach));
  EXPECT_TRUE(renderer.Sees(near_mark, {over_mark}, reach));
  EXPECT_TRUE(renderer.Sees(far_mark, {}, reach));
  // Under the table, nothing is seen; nor a point behind the camera.
  EXPECT_FALSE(renderer.Sees(Vector3d(0.5, 0, setup.apparatus.table_z - 0.05), {}, reach));
  EXPECT_FALSE(renderer.Sees(Vector3d(0.5, -3.0, 0.0), {}, reach));
}

}  // namespace
}  // namespace uphill
