// Chessboard rendering: synthetic views of a flat chessboard calibration target as a given
// camera (camera.hpp, lens distortion included) records them, with the exact image positions of
// the inner corners as ground truth. Used by the calibration tests and by the clip generator
// (tools/make_video) to write the calibration images of a synthetic clip.
//
// Target: `cols` × `rows` inner corners (OpenCV's pattern size: a 9×6 target has 10×7 squares),
// squares of side `square` metres, surrounded by a white margin of `margin_squares` squares (a
// detector needs a light border around the board), on a grey background.
// Board frame: origin at the first inner corner, x along a row of corners (corner (c, r) is at
// (c·square, r·square, 0)), y along a column, z = x × y. A board pose maps board points to the
// camera frame like CameraPose maps apparatus points.
//
// Method: inverse mapping. Every raw pixel's viewing ray (UndistortPixels) is intersected with
// the board plane and takes the colour of the square it hits. Anti-aliasing: supersampling ×
// supersampling samples per pixel, box-filtered. The rays of the samples are interpolated
// bilinearly between the rays of the pixel corners (computed once per camera): the lens maps
// are smooth, the interpolation error is below 1e-4 px for |k1| ≤ 0.3 at 1280×720 (second
// derivative of the map × pixel²/8). Then optional Gaussian blur (cv::GaussianBlur, the lens's
// and the sensor's blur) and additive Gaussian noise (seeded: the same options give the same
// image on every machine).
//
// Accuracy of the ground truth: corners are projected with ProjectApparatusPoints (OpenCV's
// closed form). What a detector finds differs from them by its own error plus the
// rasterisation: cv::cornerSubPix on 1280×720 views blurred by 0.7 px finds them within
// 0.05 px RMS (0.25 px worst) at 3× supersampling, 0.03 px RMS (0.12 px worst) at 6×; without
// supersampling 0.2 px RMS (aliasing of the square edges).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "vision/camera.hpp"

namespace uphill {

struct ChessboardTarget {
  int cols = 9, rows = 6;  // inner corners across, down
  double square = 0.02;    // side of a square, metres
};

// Throws InputError ("--cols", "--rows", "--square") unless cols, rows ≥ 2 and square > 0.
void ValidateTarget(const ChessboardTarget& target);

// The inner corners in the board frame, metres, row by row (corner (c, r) at index r·cols + c),
// the order of cv::findChessboardCorners on an upright board.
std::vector<Eigen::Vector3d> ChessboardCorners(const ChessboardTarget& target);

struct ChessboardRenderOptions {
  int supersampling = 4;       // samples per pixel along each axis (1..16)
  double blur_sigma_px = 0;    // Gaussian blur after sampling; 0: none
  double noise_sigma = 0;      // additive Gaussian noise, grey levels (of 255); 0: none
  std::uint32_t seed = 1;      // of the noise
  double margin_squares = 1;   // white border around the squares, in squares
  double black = 25, white = 230, background = 120;  // grey levels
};

struct ChessboardView {
  cv::Mat image;                          // 8-bit, one channel, camera.width × camera.height
  CameraPose board_pose;                  // board frame -> camera frame
  std::vector<Eigen::Vector2d> corners;   // raw pixels of the inner corners (ChessboardCorners order)
};

// Renders views of one target seen by one camera. Construction maps every pixel corner of the
// image to its viewing ray (one undistortion per pixel corner); each Render then traces those
// rays at 4× supersampling.
class ChessboardRenderer {
 public:
  // Throws InputError for invalid intrinsics (ValidateIntrinsics) or target (ValidateTarget).
  ChessboardRenderer(const CameraIntrinsics& camera, const ChessboardTarget& target);

  // Throws InputError when the pose puts a corner behind the camera or an option is out of range.
  // Parts of the board outside the image are simply not seen (the corners are still returned).
  ChessboardView Render(const CameraPose& board_pose, const ChessboardRenderOptions& options = {}) const;

  const CameraIntrinsics& camera() const { return camera_; }
  const ChessboardTarget& target() const { return target_; }

 private:
  CameraIntrinsics camera_;
  ChessboardTarget target_;
  // Normalised image coordinates of the ray through each pixel corner (u − ½, v − ½), row-major,
  // (width + 1) × (height + 1).
  std::vector<Eigen::Vector2d> corner_rays_;
};

struct RandomBoardPoseOptions {
  double min_tilt_deg = 15, max_tilt_deg = 45;  // angle between board normal and optical axis
  double max_spin_deg = 30;                     // rotation of the board within its plane
  double min_size = 0.35, max_size = 0.6;       // board width (with margin) / image width
  double margin_px = 8;                         // the whole board, with margin, this far inside
  double margin_squares = 1;                    // as ChessboardRenderOptions::margin_squares
};

// `count` poses, reproducible from `seed`, with the whole board (and its white margin) inside
// the image, the board centres spread over a 3 × 3 grid of image regions in turn (coverage of
// the image, as a calibration needs), tilted about random in-plane axes. Throws InputError when
// the board cannot be placed (e.g. a size range that does not fit the image).
std::vector<CameraPose> RandomBoardPoses(const CameraIntrinsics& camera, const ChessboardTarget& target,
                                         int count, std::uint32_t seed,
                                         const RandomBoardPoseOptions& options = {});

}  // namespace uphill
