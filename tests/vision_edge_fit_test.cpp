// The fast path's edge locator (src/vision/internal/edge_fit.hpp) on frames drawn here. Truth:
// each pixel's share of a 16×16 grid of sub-pixel viewing rays that meet the sphere (a
// ray–sphere intersection through UndistortPixels, not the locator's tangent-cone geometry),
// blended in linear light and encoded as sRGB; the centre drawn is the centre to find.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>

#include "internal/edge_fit.hpp"
#include "outline_geometry_support.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kRadius = 0.0127;  // m: a 1-inch ball, about 19 px across its radius here

double SrgbEncode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

// The sphere at (x, 0, z) in front of a plain background: body and background colours in linear
// RGB (0..1), drawn as 8-bit BGR.
cv::Mat DrawBall(const OutlineGeometry& g, double x, double z, const Vector3d& body_rgb, const Vector3d& back_rgb) {
  constexpr int kSub = 16;
  const Vector2d centre = g.Project(x, z);
  cv::Mat frame(g.cal.camera.height, g.cal.camera.width, CV_8UC3);
  const Vector3d eye = CameraCentre(g.cal.pose), c(x, 0, z);
  for (int v = 0; v < frame.rows; ++v)
    for (int u = 0; u < frame.cols; ++u) {
      double share = 0;
      if ((Vector2d(u, v) - centre).norm() < 40) {
        std::vector<Vector2d> raw;
        for (int i = 0; i < kSub; ++i)
          for (int j = 0; j < kSub; ++j) raw.emplace_back(u - 0.5 + (i + 0.5) / kSub, v - 0.5 + (j + 0.5) / kSub);
        for (const Vector2d& m : UndistortPixels(g.cal.camera, raw)) {
          const Vector3d ray = (g.to_apparatus * Vector3d(m.x(), m.y(), 1)).normalized();
          const Vector3d to_c = c - eye;
          share += (to_c - to_c.dot(ray) * ray).norm() < kRadius;
        }
        share /= kSub * kSub;
      }
      const Vector3d rgb = share * body_rgb + (1 - share) * back_rgb;
      for (int ch = 0; ch < 3; ++ch)
        frame.at<cv::Vec3b>(v, u)[2 - ch] = static_cast<std::uint8_t>(std::lround(255 * SrgbEncode(rgb[ch])));
    }
  return frame;
}

double Luminance(const Vector3d& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

struct Located {
  EdgeFitOutcome fit;
  double error_px;  // |fitted − drawn| in the image
};

Located Locate(const Vector3d& body_rgb, const Vector3d& back_rgb) {
  OutlineGeometry g = TestOutlineGeometry(kRadius);
  const cv::Mat occluder = cv::Mat::zeros(g.cal.camera.height, g.cal.camera.width, CV_8U);
  g.occluder = &occluder;
  const double x = 0.41, z = 0.105;
  const cv::Mat frame = DrawBall(g, x, z, body_rgb, back_rgb);
  EdgeFit edges(g, 96, Transfer::kSrgb);
  // Started 2 mm (about 3 px) off the drawn centre, as a prediction might be.
  const EdgeFitOutcome fit = edges.Measure(frame, x + 0.002, z - 0.001, 6);
  return {fit, fit.ok ? (g.Project(fit.x, fit.z) - g.Project(x, z)).norm() : 1e9};
}

TEST(EdgeFit, FindsAGreyOutlineToAFewHundredthsOfAPixel) {
  const Located dark_on_light = Locate({0.05, 0.05, 0.05}, {0.5, 0.45, 0.4});
  ASSERT_TRUE(dark_on_light.fit.ok);
  EXPECT_EQ(dark_on_light.fit.inliers, dark_on_light.fit.edge_points);
  EXPECT_LT(dark_on_light.error_px, 0.03);
}

// A blue ball on a green cloth of its grey: the luminance steps by 0.01 % across the outline (far
// below the locator's 2 levels per px), the colours by half of full scale. Read in hue, the outline is
// found as well as a grey one.
TEST(EdgeFit, FindsAnOutlineThatDiffersOnlyInHue) {
  const Vector3d blue(0.05, 0.15, 0.6), green(0.12, 0.1817, 0.08);
  ASSERT_LT(std::abs(Luminance(blue) - Luminance(green)), 1e-4);
  const Located isoluminant = Locate(blue, green);
  ASSERT_TRUE(isoluminant.fit.ok);
  EXPECT_GE(isoluminant.fit.inliers, 90);
  EXPECT_LT(isoluminant.error_px, 0.03);
  // Its grey contrast stays what the fast path's trust reads: next to nothing.
  EXPECT_LT(isoluminant.fit.contrast, 1.0);
}

}  // namespace
}  // namespace uphill::internal
