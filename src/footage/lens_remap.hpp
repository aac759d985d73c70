// LensRemap: a camera with lens distortion (OpenCV's model, camera.hpp) rendered by a pinhole
// renderer. The renderer draws a wider pinhole picture with the same focal lengths; every raw
// pixel then takes the pinhole picture's value where its viewing ray meets the pinhole image
// plane (cv::remap, bilinear). So the raw picture is the scene seen through exactly the OpenCV
// lens model: a point of the scene appears at ProjectApparatusPoint(camera, pose, point), which
// makes the ground truth of the footage (footage_clip.hpp) cv::projectPoints itself.
//
// The pinhole camera: fx, fy of the camera, no distortion, its image just large enough (plus
// `margin_px`) to hold the sources of every raw pixel; (cx, cy) shifted accordingly. With barrel
// distortion (k1 < 0) the raw image samples the scene no more densely than the pinhole picture
// anywhere, so bilinear interpolation loses little: it acts as a small symmetric blur (at most a
// tent of one pixel), which moves no edge on average.
//
// Accuracy: the map is UndistortPixels (< 1e-6 px round trip); a bright point rendered by POV-Ray
// and remapped lies within 0.02 px of cv::projectPoints (tests/vision_povray_test.cpp).
// Vignetting: the relative illumination (1 − s) + s·cos⁴θ of each raw pixel, θ the angle of its
// ray to the optical axis (the cos⁴ law of a thin lens; s < 1 for a phone's partial correction).
#pragma once

#include <opencv2/core.hpp>

#include "vision/camera.hpp"

namespace uphill {

class LensRemap {
 public:
  // Throws InputError for unusable intrinsics (ValidateIntrinsics).
  explicit LensRemap(const CameraIntrinsics& camera, int margin_px = 4);

  const CameraIntrinsics& camera() const { return camera_; }
  const CameraIntrinsics& pinhole() const { return pinhole_; }

  // The raw picture (camera size) of a whole pinhole picture (pinhole size); any type cv::remap takes.
  cv::Mat ToRaw(const cv::Mat& pinhole_picture) const;
  // Raw pixels `raw_box` of a pinhole picture that covers only `window` (pinhole pixels); the
  // window must hold PinholeWindow(raw_box).
  cv::Mat ToRaw(const cv::Mat& window_picture, const cv::Rect& window, const cv::Rect& raw_box) const;
  // The pinhole window holding the sources of the raw box's pixels and their bilinear neighbours.
  cv::Rect PinholeWindow(const cv::Rect& raw_box) const;

  // The largest |(x/z, y/z)| of a raw pixel's viewing ray: a point further off the axis is not in
  // the picture. (The distortion polynomial may fold such points back into the image: clamp the
  // ray to 1.05 × this before projecting when only "outside" matters.)
  double max_ray_radius() const { return max_ray_radius_; }

  // CV_32F, camera size: (1 − strength) + strength·cos⁴θ. strength in [0, 1].
  cv::Mat Vignetting(double strength) const;

 private:
  CameraIntrinsics camera_, pinhole_;
  cv::Mat map_x_, map_y_;  // CV_32F, camera size: the pinhole pixel of each raw pixel
  cv::Mat cos_field_;      // CV_32F, camera size: cos θ
  double max_ray_radius_ = 0;
};

}  // namespace uphill
