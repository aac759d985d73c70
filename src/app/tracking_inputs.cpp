#include "app/tracking_inputs.hpp"

#include <algorithm>
#include <cmath>

#include "model/input_error.hpp"

namespace uphill {

SceneCalibration ReadTrackingCalibration(const std::string& camera_path, const std::string& scene_path) {
  const CameraIntrinsics camera = ReadCameraFile(camera_path);
  SceneCalibration calibration = ReadSceneFile(scene_path);
  const CameraIntrinsics& in_scene = calibration.camera;
  auto differs = [](double a, double b) { return std::abs(a - b) > 1e-9 * std::max(1.0, std::abs(a)); };
  std::string what;
  if (camera.width != in_scene.width || camera.height != in_scene.height) what = "image size";
  else if (differs(camera.fx, in_scene.fx) || differs(camera.fy, in_scene.fy)) what = "focal length";
  else if (differs(camera.cx, in_scene.cx) || differs(camera.cy, in_scene.cy)) what = "principal point";
  else if (camera.distortion.size() != in_scene.distortion.size()) what = "distortion model";
  else
    for (size_t i = 0; i < camera.distortion.size(); ++i)
      if (differs(camera.distortion[i], in_scene.distortion[i])) what = "distortion coefficients";
  if (!what.empty())
    throw InputError(scene_path, "was calibrated with another camera than " + camera_path + " (the " + what +
                                     " differs): run `uphill calibrate scene` with this camera file");
  calibration.camera = camera;
  return calibration;
}

}  // namespace uphill
