// Tracking inputs: the calibration `uphill track` films with (docs/track.md) — the camera file of
// `calibrate camera` and the scene file of `calibrate scene`, which must have been calibrated
// with that same camera.
#pragma once

#include <string>

#include "vision/camera.hpp"

namespace uphill {

// The scene calibration of `scene_path` with the intrinsics of `camera_path`. Throws InputError
// naming the scene file when its camera (image size, focal length, principal point, distortion
// model or coefficients, compared to 1e-9 relative) is not the camera file's, and what
// ReadCameraFile and ReadSceneFile throw.
SceneCalibration ReadTrackingCalibration(const std::string& camera_path, const std::string& scene_path);

}  // namespace uphill
