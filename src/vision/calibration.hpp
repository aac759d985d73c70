// Calibration: the camera's intrinsics from views of a chessboard target, and the camera's pose
// in the apparatus frame from points of known position (calibration/README.md walks a
// technician through both).
//
// Camera (CalibrateCamera): the inner corners of each view are found by
// cv::findChessboardCornersSB (at half resolution first, for speed) + cv::cornerSubPix, then cv::calibrateCamera fits fx, fy, cx, cy and the distortion (k1, k2, p1, p2, and k3
// only with fit_k3: with the 10–20 views of a lab session k3 mostly fits noise). Accuracy on
// synthetic views (chessboard_render.hpp: 15 views 1280×720, fx = 1000 px, k1 = −0.1, 0.7 px
// blur, 1.5 grey levels noise): fx, fy within 0.02 %, cx, cy within 0.5 px, RMS reprojection
// error 0.035 px (tests/vision_calibration_test.cpp asserts 0.5 %, 3 px, 0.2 px on 12 views).
// Real views give 0.1–0.5 px; above 1 px something is wrong (motion blur, a board that is not
// flat, a wrong --cols/--rows).
//
// Scene (CalibrateScene): ≥ 4 points with their raw pixel (u, v) in a frame of the video and
// their position (x, y, z) in the apparatus frame; cv::solvePnP (SOLVEPNP_SQPNP, globally
// optimal for planar and non-planar points) then cv::solvePnPRefineLM. Accuracy: 11 apparatus
// points seen from 1.5 m with 0.2 px noise give the camera centre within 2.1 mm RMS. Points on one line leave
// the rotation about that line undetermined and are refused; coplanar points are fine.
//
// Hard cases, all refused with InputError naming the file (and row) and the rule: an image that
// cannot be read or declares more pixels than uphill decodes, images of different sizes, a square
// or a point's coordinate out of range (below, "ranges"), no usable view, fewer than 4 scene points, scene
// points on a line (in space or in the image), a pixel outside the camera's image, a frame
// whose size is not the camera's.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "vision/camera.hpp"
#include "vision/chessboard_render.hpp"

namespace uphill {

// ---- ranges ----
//
// What OpenCV's calibration is given is checked against these ranges first: far outside them its
// solvers fail on assertions (a square of 1e50 mm, points 1e80 mm from O) instead of saying what
// is wrong. The ranges hold any apparatus on a lab table and any printed chessboard with room to
// spare (docs/calibrate.md).
inline constexpr double kMinSquare = 0.1e-3;        // m: a chessboard square, 0.1 mm ...
inline constexpr double kMaxSquare = 1.0;           // m: ... to 1 m
inline constexpr double kMaxPointDistance = 100.0;  // m: each coordinate of a scene point, ±100 m

// ValidateTarget, and the square within [kMinSquare, kMaxSquare]. Throws InputError(square_name)
// naming the value in mm and the range.
void ValidateCalibrationTarget(const ChessboardTarget& target, const std::string& square_name = "--square");

// ---- camera ----

struct NamedImage {
  std::string name;  // file name, for messages
  cv::Mat image;     // 8-bit, one or three channels
};

struct CameraCalibrationOptions {
  bool fit_k3 = false;          // also fit k3 (wide-angle lenses with many views)
  int min_good_views = 10;      // fewer usable views: verdict "poor"
  double max_good_rms_px = 1;   // larger RMS reprojection error: verdict "poor"
  double min_coverage = 0.6;    // smaller fraction of a 5×5 grid of image cells with corners: "poor"
  double min_tilt_deg = 15;     // fewer than 3 views tilted this much: "poor" (fronto-parallel)
};

struct ViewDiagnostics {
  std::string name;
  bool used = false;
  std::string rejected_because;  // when not used
  double rms_px = 0;             // reprojection error of this view's corners
  double tilt_deg = 0;           // angle between the board's normal and the optical axis
  double distance_m = 0;         // camera to the board's first corner
};

struct CameraCalibration {
  CameraIntrinsics camera;
  double rms_px = 0;                   // RMS reprojection error over all corners of the used views
  Eigen::Vector4d std_dev_px;          // standard deviations of fx, fy, cx, cy from calibrateCamera
  std::vector<ViewDiagnostics> views;  // in input order
  int views_used = 0;
  double coverage = 0;                 // fraction of the 5×5 image cells holding a detected corner
  std::string verdict;                 // "good" or "poor"
  std::vector<std::string> reasons;    // why poor (empty when good)

  CalibrationSummary Summary(const ChessboardTarget& target) const;
};

// Throws InputError: no images, an empty image, images of different sizes (naming the file),
// fewer than 3 views with the board found (naming the files and why). Views where the board is
// not found are rejected and listed, the others used.
CameraCalibration CalibrateCamera(const std::vector<NamedImage>& images, const ChessboardTarget& target,
                                  const CameraCalibrationOptions& options = {});
// The same from image files (cv::imread; an unreadable file is an InputError naming it). The target
// is validated and each file's header checked against the pixel limit (vision/decode_limits.hpp)
// before any image is decoded.
CameraCalibration CalibrateCameraFromFiles(const std::vector<std::string>& paths,
                                           const ChessboardTarget& target,
                                           const CameraCalibrationOptions& options = {});

// ---- scene ----

// ScenePoint: vision/camera.hpp (the scene file keeps them).

struct ScenePointResidual {
  std::string label;
  double error_px = 0;        // distance between the given and the re-projected pixel
};

// Leave-one-out: with ≥ kMinPointsForLeaveOneOut points the pose is refitted without each point
// in turn (4 points or more remain, so that the refit is overdetermined), and the point whose
// removal lowers the RMS error of the others most is kept here. A misread point pulls the full fit
// toward itself and shifts the residuals onto good points; the pose without it does not, so it is
// the one named, even when its own residual in the full fit is small. It "explains" the error when
// its removal at least halves the RMS error and it lies more than kLeaveOneOutMinResidualPx from
// where the other points place it: then it is named in the verdict's reasons. On points projected
// through a known pose (tests/vision_calibration_test.cpp), one pixel moved by 5 px is the one
// named, whichever it is, with 0.2 px of noise on the others.
inline constexpr size_t kMinPointsForLeaveOneOut = 5;
inline constexpr double kLeaveOneOutMinResidualPx = 2;
struct LeaveOneOutCheck {
  size_t index = 0;           // into the points given
  std::string label;
  double residual_px = 0;     // its distance from where the pose fitted without it places it
                              // (infinity: that pose puts it behind the camera)
  double rms_without_px = 0;  // RMS error of the other points about that pose
  bool explains = false;      // see above
};

struct SceneCalibrationResult {
  SceneCalibration scene;
  double rms_px = 0;
  std::vector<ScenePointResidual> residuals;
  std::optional<LeaveOneOutCheck> leave_one_out;  // with ≥ kMinPointsForLeaveOneOut points
  std::string verdict;               // "good" or "poor"
  std::vector<std::string> reasons;  // why poor

  CalibrationSummary Summary() const;
};

// Throws InputError (see the header comment; also a coordinate of a point beyond ±kMaxPointDistance,
// named with its value in mm). `frame_width`/`frame_height` > 0: the size of the
// frame the pixels were read from, which must be the camera's; 0: not checked.
SceneCalibrationResult CalibrateScene(const CameraIntrinsics& camera, const std::vector<ScenePoint>& points,
                                      int frame_width = 0, int frame_height = 0);

// Scene from a chessboard laid flat on the table: its first inner corner at `origin` (apparatus
// frame, metres), its rows of corners along `x_axis`, its columns along `y_axis` (unit vectors of
// the apparatus frame, orthogonal). The board's inner corners become the scene points.
// Throws InputError when the board is not found in the image or the axes are not orthonormal.
SceneCalibrationResult CalibrateSceneFromChessboard(const CameraIntrinsics& camera, const NamedImage& image,
                                                    const ChessboardTarget& target,
                                                    const Eigen::Vector3d& origin,
                                                    const Eigen::Vector3d& x_axis,
                                                    const Eigen::Vector3d& y_axis);

// The inner corners of a target found in one image (raw pixels, findChessboardCorners order), or
// empty when the board is not found.
std::vector<Eigen::Vector2d> FindChessboardCorners(const cv::Mat& image, const ChessboardTarget& target);

// A printable image of the target: `pixels_per_square` pixels per square, a white margin of one
// square. Print at a scale where a square measures `target.square` (and measure it after printing).
cv::Mat ChessboardTargetImage(const ChessboardTarget& target, int pixels_per_square);

}  // namespace uphill
