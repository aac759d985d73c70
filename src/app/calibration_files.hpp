// Calibrating from the files a user has (docs/calibrate.md): the scene's pose from a points file
// or from a chessboard image lying in the scene, and the plain-text summaries that
// `uphill calibrate camera` and `uphill calibrate scene` print after writing their file (the
// camera's intrinsics with their standard deviations, the views, the pose, the residuals, the
// verdict and its reasons). Lengths in the summaries are in mm, angles in degrees, pixels raw.
#pragma once

#include <Eigen/Core>
#include <string>

#include "vision/calibration.hpp"

namespace uphill {

// The camera's pose from POINTS.csv (app/calibration_inputs.hpp). `frame_path`, when not empty:
// a frame of the video, whose size must be the camera's. `inputs` (optional) receives the points
// as the scene file keeps them (each named by its `name` cell, or "row N"). Throws InputError
// naming the points file, or the frame and the camera file, and the rule broken.
SceneCalibrationResult CalibrateSceneFromPointsFile(const CameraIntrinsics& camera, const std::string& camera_name,
                                                    const std::string& points_path, const std::string& frame_path,
                                                    SceneInputs* inputs = nullptr);

// The camera's pose from an image of a chessboard lying in the scene: its first inner corner at
// `origin` (m, apparatus frame), its rows along `x_axis` and its columns along `y_axis` (unit
// apparatus axes, perpendicular). Throws InputError naming the image or the axes.
SceneCalibrationResult CalibrateSceneFromBoardFile(const CameraIntrinsics& camera, const std::string& image_path,
                                                   const ChessboardTarget& target, const Eigen::Vector3d& origin,
                                                   const Eigen::Vector3d& x_axis, const Eigen::Vector3d& y_axis);

// What `calibrate camera` prints: size, fx, fy, cx, cy with their standard deviations, the
// distortion coefficients (k3 marked fixed unless fitted), RMS error, coverage, each view, and
// the verdict with its reasons.
std::string CameraCalibrationText(const CameraCalibration& c, const ChessboardTarget& target, bool fit_k3);

// What `calibrate scene` prints: the camera's centre and viewing direction in the apparatus
// frame, its distance to O, the RMS error, each point's residual, the leave-one-out check (the
// point whose removal lowers the RMS error most, vision/calibration.hpp) and the verdict.
std::string SceneCalibrationText(const SceneCalibrationResult& r, const std::string& camera_name);

}  // namespace uphill
