// Scene calibration by clicks (the page of `uphill serve`, docs/serve.md "Calibrate the scene"):
// the apparatus points the page offers for a setting, and the pose solved from the clicks so far,
// exactly as `uphill calibrate scene --points` solves it (vision/calibration.hpp CalibrateScene),
// with what the page draws over the frame: each point re-projected, its residual, and the model's
// path of the body's centre.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "model/scene.hpp"
#include "vision/apparatus_points.hpp"
#include "vision/calibration.hpp"

namespace uphill {

// The points of a setting (vision/apparatus_points.hpp) from its rails and crossbar distance.
// Throws InputError("L") when the setting gives the rails by angles only (no crossbar distance:
// then only O and typed points can be clicked), InputError("marks") naming a mark that is not
// strictly between O and the crossbar (0 < x < L), or the configuration's own InputError.
std::vector<ApparatusPoint> SettingCalibrationPoints(const Configuration& setting, double table_z,
                                                     const std::vector<double>& marks_x);

// What the page sends: the clicks so far, and what the points were offered from.
struct SceneClicks {
  std::vector<ScenePoint> clicks;         // ≥ 4: label = the point's name, raw pixel, apparatus position
  std::vector<ApparatusPoint> unclicked;  // offered but not clicked yet: shown where the pose puts them
  std::vector<double> marks_x;            // m, the marks the points were offered from (kept in the file)
  std::optional<double> table_z;          // m, the table's height they were offered with (kept too)
};

struct SceneClicksSolution {
  SceneCalibrationResult calibration;        // pose, RMS, residuals (one per click), verdict, leave-one-out
  std::vector<Eigen::Vector2d> reprojected;  // raw pixel of each click's point through the pose
  // The unclicked points in view through the pose (VisibleApparatusPoints), with their raw pixels:
  // where to look for them.
  std::vector<ApparatusPoint> expected;
  // The apparatus axes from O through the pose, for telling the rails apart: "O", "+x" (toward the
  // crossbar) and "+y (left rail)" at kAxisLength from O, those in view.
  std::vector<ApparatusPoint> axes;
  // The body's centre along the model's path (x from x_low to x_max, 200 steps, y = 0, z from
  // the scene) through the pose, raw pixels; the part behind the camera is left out. Empty
  // without a scene.
  std::vector<Eigen::Vector2d> centre_path;
  std::string scene_file;                    // the scene file's text (uphill-scene/1), with its inputs
};
inline constexpr double kAxisLength = 0.1;  // m

// Solves the pose from the clicks. `frame_width` and `frame_height`: the size of the video's
// frames, which must be the camera's (0: unchecked). The scene file keeps the clicks, the marks
// and the table's height, so that the page can restore them. Throws InputError as
// CalibrateScene: fewer than 4 points ("points"), points on one line, a pixel outside the image,
// a frame whose size is not the camera's ("frame").
SceneClicksSolution SolveSceneClicks(const CameraIntrinsics& camera, const SceneClicks& request, int frame_width,
                                     int frame_height, const std::optional<Scene>& scene);

}  // namespace uphill
