#include "app/scene_clicks.hpp"

#include <sstream>

#include "model/input_error.hpp"

namespace uphill {

std::vector<ApparatusPoint> SettingCalibrationPoints(const Configuration& setting, double table_z,
                                                     const std::vector<double>& marks_x) {
  const Rails rails = setting.MakeRails();
  const std::optional<double> crossbar = setting.CrossbarDistance();
  if (!crossbar)
    throw InputError("L", "the rails are given by their angles: the points at the crossbar need L, H and D");
  const auto mm = [](double metres) {
    std::ostringstream out;
    out << metres * 1000;
    return out.str() + " mm";
  };
  for (std::size_t i = 0; i < marks_x.size(); ++i)
    if (!(marks_x[i] > 0 && marks_x[i] < *crossbar))
      throw InputError("marks", "mark " + std::to_string(i + 1) + " at " + mm(marks_x[i]) +
                                    " is not on the rails between O and the crossbar (more than 0 mm and less than " +
                                    mm(*crossbar) + ")");
  return ApparatusCalibrationPoints(rails, *crossbar, table_z, marks_x);
}

SceneClicksSolution SolveSceneClicks(const CameraIntrinsics& camera, const SceneClicks& request, int frame_width,
                                     int frame_height, const std::optional<Scene>& scene) {
  SceneClicksSolution out;
  const std::vector<ScenePoint>& clicks = request.clicks;
  out.calibration = CalibrateScene(camera, clicks, frame_width, frame_height);
  const CameraPose& pose = out.calibration.scene.pose;
  std::vector<Eigen::Vector3d> positions;
  for (const ScenePoint& p : clicks) positions.push_back(p.position);
  out.reprojected = ProjectApparatusPoints(camera, pose, positions);
  out.expected = VisibleApparatusPoints(camera, pose, request.unclicked);
  out.axes = VisibleApparatusPoints(camera, pose,
                                    {{"O", Eigen::Vector3d::Zero()},
                                     {"+x", Eigen::Vector3d(kAxisLength, 0, 0)},
                                     {"+y (left rail)", Eigen::Vector3d(0, kAxisLength, 0)}});
  if (scene) {
    std::vector<Eigen::Vector3d> path;
    for (int i = 0; i <= 200; ++i) {
      const double x = scene->x_low() + (scene->x_max() - scene->x_low()) * i / 200.0;
      const Eigen::Vector3d p(x, 0, scene->At(x).z);
      if ((pose.rotation * p + pose.translation).z() > 0) path.push_back(p);
    }
    out.centre_path = ProjectApparatusPoints(camera, pose, path);
  }
  CalibrationSummary summary = out.calibration.Summary();
  summary.method = "points clicked in a frame of the video (uphill serve); " + summary.method;
  out.scene_file =
      SceneFileText(out.calibration.scene, summary, SceneInputs{clicks, request.marks_x, request.table_z});
  return out;
}

}  // namespace uphill
