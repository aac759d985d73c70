#include "footage/lens_remap.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "model/input_error.hpp"

namespace uphill {

LensRemap::LensRemap(const CameraIntrinsics& camera, int margin_px) : camera_(camera) {
  ValidateIntrinsics(camera, "camera");
  const int w = camera.width, h = camera.height;
  std::vector<Eigen::Vector2d> pixels;
  pixels.reserve(static_cast<size_t>(w) * h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) pixels.emplace_back(u, v);
  const std::vector<Eigen::Vector2d> rays = UndistortPixels(camera, pixels);
  // Pinhole coordinates with the camera's (cx, cy) first; then shift so that all fit.
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (const Eigen::Vector2d& n : rays) {
    const double pu = camera.fx * n.x() + camera.cx, pv = camera.fy * n.y() + camera.cy;
    u0 = std::min(u0, pu), u1 = std::max(u1, pu), v0 = std::min(v0, pv), v1 = std::max(v1, pv);
    max_ray_radius_ = std::max(max_ray_radius_, n.norm());
  }
  const double shift_u = margin_px - std::floor(u0), shift_v = margin_px - std::floor(v0);
  pinhole_.fx = camera.fx;
  pinhole_.fy = camera.fy;
  pinhole_.cx = camera.cx + shift_u;
  pinhole_.cy = camera.cy + shift_v;
  pinhole_.width = static_cast<int>(std::ceil(u1 + shift_u)) + margin_px + 1;
  pinhole_.height = static_cast<int>(std::ceil(v1 + shift_v)) + margin_px + 1;
  map_x_.create(h, w, CV_32F);
  map_y_.create(h, w, CV_32F);
  cos_field_.create(h, w, CV_32F);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d& n = rays[static_cast<size_t>(v) * w + u];
      map_x_.at<float>(v, u) = static_cast<float>(pinhole_.fx * n.x() + pinhole_.cx);
      map_y_.at<float>(v, u) = static_cast<float>(pinhole_.fy * n.y() + pinhole_.cy);
      cos_field_.at<float>(v, u) = static_cast<float>(1.0 / std::sqrt(1.0 + n.squaredNorm()));
    }
}

cv::Mat LensRemap::ToRaw(const cv::Mat& pinhole_picture) const {
  cv::Mat out;
  cv::remap(pinhole_picture, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

cv::Mat LensRemap::ToRaw(const cv::Mat& window_picture, const cv::Rect& window, const cv::Rect& raw_box) const {
  cv::Mat mx = map_x_(raw_box) - static_cast<float>(window.x);
  cv::Mat my = map_y_(raw_box) - static_cast<float>(window.y);
  cv::Mat out;
  cv::remap(window_picture, out, mx, my, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

cv::Rect LensRemap::PinholeWindow(const cv::Rect& raw_box) const {
  double x0, x1, y0, y1;
  cv::minMaxLoc(map_x_(raw_box), &x0, &x1);
  cv::minMaxLoc(map_y_(raw_box), &y0, &y1);
  const cv::Rect window(static_cast<int>(std::floor(x0)) - 1, static_cast<int>(std::floor(y0)) - 1,
                        static_cast<int>(std::ceil(x1) - std::floor(x0)) + 3,
                        static_cast<int>(std::ceil(y1) - std::floor(y0)) + 3);
  return window & cv::Rect(0, 0, pinhole_.width, pinhole_.height);
}

cv::Mat LensRemap::Vignetting(double strength) const {
  if (!(strength >= 0 && strength <= 1)) throw InputError("vignetting", "must be in [0, 1]");
  cv::Mat c2 = cos_field_.mul(cos_field_);
  cv::Mat out = c2.mul(c2) * strength + (1.0 - strength);
  return out;
}

}  // namespace uphill
