#include "app/calibration_files.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "app/calibration_inputs.hpp"
#include "model/input_error.hpp"
#include "vision/decode_limits.hpp"
#include "vision/library_logs.hpp"

namespace uphill {
namespace {

std::string Num(double v, int precision = 6) {
  std::ostringstream out;
  out.precision(precision);
  out << v;
  return out.str();
}

std::string Fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
}

void Row(std::ostream& out, const std::string& name, const std::string& value) {
  out << "  " << std::left << std::setw(34) << name << value << "\n";
}

void Verdict(std::ostream& out, const std::string& verdict, const std::vector<std::string>& reasons) {
  out << "verdict: " << verdict << "\n";
  for (const auto& r : reasons) out << "  * " << r << "\n";
}

cv::Mat ReadGreyImage(const std::string& path, const std::string& label) {
  CheckImagePixels(path, label + " " + path);
  QuietVideoLibraryLogs();
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw InputError(label + " " + path, "cannot be read as an image");
  return image;
}

}  // namespace

SceneCalibrationResult CalibrateSceneFromPointsFile(const CameraIntrinsics& camera, const std::string& camera_name,
                                                    const std::string& points_path, const std::string& frame_path,
                                                    SceneInputs* inputs) {
  int frame_width = 0, frame_height = 0;
  if (!frame_path.empty()) {
    const cv::Mat frame = ReadGreyImage(frame_path, "--frame");
    frame_width = frame.cols;
    frame_height = frame.rows;
  }
  try {
    std::vector<std::string> names;
    const std::vector<ScenePoint> points = ReadScenePoints(points_path, &names);
    SceneCalibrationResult result = CalibrateScene(camera, points, frame_width, frame_height);
    if (inputs) {
      inputs->points = points;
      for (size_t i = 0; i < points.size(); ++i) inputs->points[i].label = names[i];
    }
    return result;
  } catch (const InputError& e) {
    // The library names rows (labels) or "points"/"frame"; say which file was meant.
    const std::string& q = e.quantity();
    if (q == "points") throw InputError(points_path + ": points", e.rule());
    if (q == "frame") throw InputError("--frame " + frame_path, e.rule() + " (camera file " + camera_name + ")");
    throw;
  }
}

SceneCalibrationResult CalibrateSceneFromBoardFile(const CameraIntrinsics& camera, const std::string& image_path,
                                                   const ChessboardTarget& target, const Eigen::Vector3d& origin,
                                                   const Eigen::Vector3d& x_axis, const Eigen::Vector3d& y_axis) {
  if (x_axis.dot(y_axis) != 0) throw InputError("--board-x-axis/--board-y-axis", "must be perpendicular");
  return CalibrateSceneFromChessboard(camera, {image_path, ReadGreyImage(image_path, "--board-image")}, target, origin,
                                      x_axis, y_axis);
}

std::string CameraCalibrationText(const CameraCalibration& c, const ChessboardTarget& target, bool fit_k3) {
  std::ostringstream out;
  const CameraIntrinsics& k = c.camera;
  out << "camera calibration: " << c.views_used << " of " << c.views.size() << " views used, chessboard "
      << target.cols << "×" << target.rows << " inner corners, " << Num(target.square * 1000) << " mm squares\n";
  Row(out, "image size", std::to_string(k.width) + " × " + std::to_string(k.height) + " px");
  Row(out, "fx (focal length, x)", Fixed(k.fx, 2) + " px   (± " + Num(c.std_dev_px(0), 2) + ")");
  Row(out, "fy (focal length, y)", Fixed(k.fy, 2) + " px   (± " + Num(c.std_dev_px(1), 2) + ")");
  Row(out, "cx (principal point, x)", Fixed(k.cx, 2) + " px   (± " + Num(c.std_dev_px(2), 2) + ")");
  Row(out, "cy (principal point, y)", Fixed(k.cy, 2) + " px   (± " + Num(c.std_dev_px(3), 2) + ")");
  static const char* kNames[] = {"k1", "k2", "p1", "p2", "k3"};
  for (size_t i = 0; i < k.distortion.size() && i < 5; ++i)
    Row(out, std::string("distortion ") + kNames[i], Num(k.distortion[i], 5) + (i == 4 && !fit_k3 ? "   (fixed)" : ""));
  Row(out, "RMS reprojection error", Fixed(c.rms_px, 3) + " px");
  Row(out, "image coverage", Fixed(100 * c.coverage, 0) + " % (cells of a 5×5 grid with corners)");
  out << "  views:\n";
  for (const auto& v : c.views) {
    if (v.used)
      out << "    " << v.name << ": RMS " << Fixed(v.rms_px, 3) << " px, tilt " << Fixed(v.tilt_deg, 1) << "°, distance "
          << Fixed(v.distance_m * 1000, 0) << " mm\n";
    else
      out << "    " << v.name << ": rejected, " << v.rejected_because << "\n";
  }
  Verdict(out, c.verdict, c.reasons);
  return out.str();
}

std::string SceneCalibrationText(const SceneCalibrationResult& r, const std::string& camera_name) {
  std::ostringstream out;
  const CameraPose& pose = r.scene.pose;
  const Eigen::Vector3d centre = CameraCentre(pose);
  const Eigen::Vector3d axis = pose.rotation.row(2).transpose();
  const double degree = std::numbers::pi / 180;
  out << "scene calibration: " << r.residuals.size() << " points, camera " << camera_name << "\n";
  Row(out, "camera centre (apparatus frame)", "x = " + Fixed(centre.x() * 1000, 1) + " mm, y = " +
                                                  Fixed(centre.y() * 1000, 1) + " mm, z = " +
                                                  Fixed(centre.z() * 1000, 1) + " mm");
  Row(out, "distance to O", Fixed(centre.norm() * 1000, 1) + " mm");
  Row(out, "viewing direction", "(" + Fixed(axis.x(), 4) + ", " + Fixed(axis.y(), 4) + ", " + Fixed(axis.z(), 4) +
                                    "): " + Fixed(std::asin(std::clamp(-axis.z(), -1.0, 1.0)) / degree, 1) +
                                    "° below horizontal, azimuth " + Fixed(std::atan2(axis.y(), axis.x()) / degree, 1) +
                                    "° from +x");
  Row(out, "RMS reprojection error", Fixed(r.rms_px, 3) + " px");
  out << "  residuals:\n";
  for (const auto& p : r.residuals) out << "    " << p.label << ": " << Fixed(p.error_px, 3) << " px\n";
  if (const auto& check = r.leave_one_out)
    out << "  leave-one-out: without " << check->label << " the RMS error is " << Fixed(check->rms_without_px, 3)
        << " px (the largest drop); it lies "
        << (std::isfinite(check->residual_px) ? Fixed(check->residual_px, 2) + " px from where the other points place it"
                                              : "behind the camera in the pose the other points give")
        << (check->explains ? ": check this point" : "") << "\n";
  Verdict(out, r.verdict, r.reasons);
  return out.str();
}

}  // namespace uphill
