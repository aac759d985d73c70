// Frames with a sphere drawn by ray casting, for the tests of the tracker's parts: each pixel's
// share of a 16×16 grid of sub-pixel viewing rays that meet the sphere (a ray–sphere intersection
// through UndistortPixels, not the tracker's tangent-cone geometry), blended in linear light with
// what lies behind it and encoded as sRGB.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "internal/outline_fit.hpp"
#include "vision/camera.hpp"

namespace uphill::internal {

inline double SrgbEncode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

// The sphere of radius `radius` at (x, 0, z) over a background given per pixel (linear RGB, 0..1),
// as 8-bit BGR; `body_rgb` empty draws the background alone. The sphere is cast within 40 px of its
// centre's image.
inline cv::Mat DrawBallOver(const OutlineGeometry& g, double radius, double x, double z, const Eigen::Vector3d* body_rgb,
                            const std::function<Eigen::Vector3d(int u, int v)>& back_rgb) {
  constexpr int kSub = 16;
  const Eigen::Vector2d centre = g.Project(x, z);
  cv::Mat frame(g.cal.camera.height, g.cal.camera.width, CV_8UC3);
  const Eigen::Vector3d eye = CameraCentre(g.cal.pose), c(x, 0, z);
  for (int v = 0; v < frame.rows; ++v)
    for (int u = 0; u < frame.cols; ++u) {
      double share = 0;
      if (body_rgb && (Eigen::Vector2d(u, v) - centre).norm() < 40) {
        std::vector<Eigen::Vector2d> raw;
        for (int i = 0; i < kSub; ++i)
          for (int j = 0; j < kSub; ++j) raw.emplace_back(u - 0.5 + (i + 0.5) / kSub, v - 0.5 + (j + 0.5) / kSub);
        for (const Eigen::Vector2d& m : UndistortPixels(g.cal.camera, raw)) {
          const Eigen::Vector3d ray = (g.to_apparatus * Eigen::Vector3d(m.x(), m.y(), 1)).normalized();
          const Eigen::Vector3d to_c = c - eye;
          share += (to_c - to_c.dot(ray) * ray).norm() < radius;
        }
        share /= kSub * kSub;
      }
      const Eigen::Vector3d rgb = share > 0 ? Eigen::Vector3d(share * *body_rgb + (1 - share) * back_rgb(u, v)) : back_rgb(u, v);
      for (int ch = 0; ch < 3; ++ch)
        frame.at<cv::Vec3b>(v, u)[2 - ch] = static_cast<std::uint8_t>(std::lround(255 * SrgbEncode(rgb[ch])));
    }
  return frame;
}

}  // namespace uphill::internal
