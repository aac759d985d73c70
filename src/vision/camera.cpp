#include "vision/camera.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <set>

#include "io/atomic_file.hpp"
#include "io/json_file.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using nlohmann::json;
using ordered_json = nlohmann::ordered_json;  // written files keep the documented key order

constexpr const char* kCameraFormat = "uphill-camera/1";
constexpr const char* kSceneFormat = "uphill-scene/1";

// cv::undistortPoints stops when the re-projected pixel is within epsilon of the given one.
// A fixed-point iteration that contracts by a factor ~0.3 per step at the corners of a strongly
// distorted image reaches 1e-9 px in ~20 steps; 200 leaves room for worse lenses.
const cv::TermCriteria kUndistortCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200,
                                          1e-9);

cv::Matx33d CameraMatrix(const CameraIntrinsics& c) {
  return cv::Matx33d(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

cv::Mat Distortion(const CameraIntrinsics& c) {
  if (c.distortion.empty()) return cv::Mat();
  return cv::Mat(c.distortion, /*copyData=*/true);
}

void RequireInFront(const Eigen::Vector3d& p) {
  if (!p.allFinite()) throw InputError("point", "must be finite");
  if (!(p.z() > 0))
    throw InputError("point", "must lie in front of the camera (z > 0 in the camera frame, got z = " +
                                  std::to_string(p.z()) + " m)");
}

// OpenCV's lens model as cv::projectPoints documents it, for the coefficient counts it has
// without the thin prism and the tilted sensor (0, 4, 5, 8: k1 k2 p1 p2 [k3 [k4 k5 k6]]).
// cv::projectPoints costs microseconds a call in set-up alone, and the tracker projects single
// points many times a frame; the same arithmetic agrees with it to rounding
// (tests/vision_camera_test.cpp, against cv::projectPoints). Other counts go through OpenCV.
bool HasPlainLensModel(const CameraIntrinsics& c) {
  const std::size_t n = c.distortion.size();
  return n == 0 || n == 4 || n == 5 || n == 8;
}

// Distortion coefficient i in OpenCV's order (0 where the camera has fewer).
double Coefficient(const CameraIntrinsics& c, std::size_t i) { return i < c.distortion.size() ? c.distortion[i] : 0.0; }

// The radial factor (1 + k1·r² + k2·r⁴ + k3·r⁶)/(1 + k4·r² + k5·r⁴ + k6·r⁶) at r² = r2.
double RadialFactor(const CameraIntrinsics& c, double r2) {
  const auto k = [&](std::size_t i) { return Coefficient(c, i); };
  const double r4 = r2 * r2, r6 = r4 * r2;
  return (1 + k(0) * r2 + k(1) * r4 + k(4) * r6) / (1 + k(5) * r2 + k(6) * r4 + k(7) * r6);
}

Eigen::Vector2d ProjectWithPlainLensModel(const CameraIntrinsics& c, const Eigen::Vector3d& p) {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  if (c.distortion.empty()) return {c.fx * x + c.cx, c.fy * y + c.cy};
  const auto k = [&](std::size_t i) { return Coefficient(c, i); };
  const double r2 = x * x + y * y;
  const double radial = RadialFactor(c, r2);
  const double xd = x * radial + 2 * k(2) * x * y + k(3) * (r2 + 2 * x * x);
  const double yd = y * radial + k(2) * (r2 + 2 * y * y) + 2 * k(3) * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

// Raw pixels of points already in the camera frame (each checked to be in front).
std::vector<Eigen::Vector2d> ProjectCameraFramePoints(const CameraIntrinsics& camera,
                                                      const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return {};
  if (HasPlainLensModel(camera)) {
    std::vector<Eigen::Vector2d> out;
    out.reserve(points.size());
    for (const auto& p : points) {
      RequireInFront(p);
      out.push_back(ProjectWithPlainLensModel(camera, p));
    }
    return out;
  }
  std::vector<cv::Point3d> object;
  object.reserve(points.size());
  for (const auto& p : points) {
    RequireInFront(p);
    object.emplace_back(p.x(), p.y(), p.z());
  }
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), CameraMatrix(camera),
                    Distortion(camera), image);
  std::vector<Eigen::Vector2d> out;
  out.reserve(image.size());
  for (const auto& q : image) out.emplace_back(q.x, q.y);
  return out;
}

// ---- JSON ----


// The stem of a key with a unit suffix: "fx_px" -> "fx", "translation_m" -> "translation".
std::string Stem(const std::string& key) {
  const size_t underscore = key.rfind('_');
  return underscore == std::string::npos ? key : key.substr(0, underscore);
}

// Unknown keys are refused (a misspelt key would otherwise be silently ignored); a known key
// with another unit suffix ("fx_mm" for "fx_px") gets a message saying so.
void CheckKeys(const json& object, const std::set<std::string>& allowed, const std::string& context) {
  if (!object.is_object()) throw InputError(context, "must be a JSON object");
  for (const auto& [key, value] : object.items()) {
    if (allowed.count(key)) continue;
    for (const auto& known : allowed)
      if (known != Stem(known) && Stem(known) == Stem(key))
        throw InputError(context + "." + key,
                         "unit does not match: the file format has " + known + " (units in the key)");
    throw InputError(context + "." + key, "unknown key");
  }
}

const json& Member(const json& object, const std::string& key, const std::string& context) {
  if (!object.contains(key)) throw InputError(context + "." + key, "is missing");
  return object.at(key);
}

double Number(const json& value, const std::string& context) {
  if (!value.is_number()) throw InputError(context, "must be a number (got " + std::string(value.type_name()) + ")");
  const double v = value.get<double>();
  if (!std::isfinite(v)) throw InputError(context, "must be finite");
  return v;
}

int PositiveInteger(const json& value, const std::string& context) {
  if (!value.is_number_integer() || value.get<long long>() <= 0 || value.get<long long>() > 1'000'000)
    throw InputError(context, "must be a positive whole number of pixels (got " + value.dump() + ")");
  return value.get<int>();
}

std::vector<double> Numbers(const json& value, const std::string& context) {
  if (!value.is_array()) throw InputError(context, "must be an array of numbers");
  std::vector<double> out;
  for (size_t i = 0; i < value.size(); ++i)
    out.push_back(Number(value[i], context + "[" + std::to_string(i) + "]"));
  return out;
}

const std::set<std::string> kIntrinsicKeys = {"image_width_px", "image_height_px", "fx_px", "fy_px",
                                              "cx_px", "cy_px", "distortion"};

CameraIntrinsics IntrinsicsFromJson(const json& j, const std::string& context,
                                    const std::set<std::string>& other_keys) {
  std::set<std::string> allowed = kIntrinsicKeys;
  allowed.insert(other_keys.begin(), other_keys.end());
  CheckKeys(j, allowed, context);
  CameraIntrinsics c;
  c.width = PositiveInteger(Member(j, "image_width_px", context), context + ".image_width_px");
  c.height = PositiveInteger(Member(j, "image_height_px", context), context + ".image_height_px");
  c.fx = Number(Member(j, "fx_px", context), context + ".fx_px");
  c.fy = Number(Member(j, "fy_px", context), context + ".fy_px");
  c.cx = Number(Member(j, "cx_px", context), context + ".cx_px");
  c.cy = Number(Member(j, "cy_px", context), context + ".cy_px");
  if (j.contains("distortion")) c.distortion = Numbers(j.at("distortion"), context + ".distortion");
  ValidateIntrinsics(c, context);
  return c;
}

ordered_json IntrinsicsToJson(const CameraIntrinsics& c) {
  return ordered_json{{"image_width_px", c.width}, {"image_height_px", c.height}, {"fx_px", c.fx},
              {"fy_px", c.fy},           {"cx_px", c.cx},               {"cy_px", c.cy},
              {"distortion", c.distortion}};
}

ordered_json SummaryToJson(const CalibrationSummary& s) {
  ordered_json j{{"method", s.method}};
  j["rms_px"] = s.rms_px >= 0 ? ordered_json(s.rms_px) : ordered_json(nullptr);
  j["verdict"] = s.verdict;
  j["reasons"] = s.reasons;
  j["inputs"] = s.inputs;
  return j;
}

void CheckFormat(const json& j, const std::string& path, const char* expected) {
  if (!j.is_object()) throw InputError(path, "must hold a JSON object");
  const json& format = Member(j, "format", path);
  if (!format.is_string() || format.get<std::string>() != expected)
    throw InputError(path + ".format", std::string("must be \"") + expected + "\" (got " + format.dump() + ")");
}

void ValidateRotation(const Eigen::Matrix3d& r, const std::string& context) {
  if (!r.allFinite()) throw InputError(context, "must be finite");
  const double error = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-6)
    throw InputError(context, "is not orthonormal (|RᵀR − I| = " + std::to_string(error) + " > 1e-6)");
  if (r.determinant() < 0) throw InputError(context, "is a reflection (determinant −1), not a rotation");
}


}  // namespace

void ValidateIntrinsics(const CameraIntrinsics& c, const std::string& context) {
  if (c.width <= 0 || c.height <= 0)
    throw InputError(context + ".image size", "must be > 0 pixels (got " + std::to_string(c.width) + "×" +
                                                  std::to_string(c.height) + ")");
  if (!(std::isfinite(c.fx) && c.fx > 0)) throw InputError(context + ".fx", "must be > 0 and finite");
  if (!(std::isfinite(c.fy) && c.fy > 0)) throw InputError(context + ".fy", "must be > 0 and finite");
  if (!std::isfinite(c.cx)) throw InputError(context + ".cx", "must be finite");
  if (!std::isfinite(c.cy)) throw InputError(context + ".cy", "must be finite");
  const size_t n = c.distortion.size();
  if (n != 0 && n != 4 && n != 5 && n != 8)
    throw InputError(context + ".distortion",
                     "must hold 0, 4, 5 or 8 coefficients (k1, k2, p1, p2[, k3[, k4, k5, k6]]), got " +
                         std::to_string(n));
  for (double d : c.distortion)
    if (!std::isfinite(d)) throw InputError(context + ".distortion", "coefficients must be finite");
}

double LensModelReach(const CameraIntrinsics& camera) {
  constexpr double kStep = 1e-3, kLimit = 5;
  double previous = 0;
  for (double r = kStep; r <= kLimit; r += kStep) {
    const double m = r * RadialFactor(camera, r * r);
    if (!(m > previous)) return r - kStep;
    previous = m;
  }
  return std::numeric_limits<double>::infinity();
}

Eigen::Vector2d ProjectCameraPoint(const CameraIntrinsics& camera, const Eigen::Vector3d& point) {
  if (HasPlainLensModel(camera)) {
    RequireInFront(point);
    return ProjectWithPlainLensModel(camera, point);
  }
  return ProjectCameraFramePoints(camera, {point}).front();
}

Eigen::Vector2d ProjectApparatusPoint(const CameraIntrinsics& camera, const CameraPose& pose,
                                      const Eigen::Vector3d& point) {
  return ProjectCameraPoint(camera, pose.rotation * point + pose.translation);
}

CameraPose LookAtPose(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  if (!centre.allFinite() || !target.allFinite() || !up.allFinite())
    throw InputError("camera pose", "centre, target and up must be finite");
  const Eigen::Vector3d view = target - centre;
  if (!(view.norm() > 0)) throw InputError("camera pose", "the target must differ from the camera centre");
  const Eigen::Vector3d z = view.normalized();
  const Eigen::Vector3d x_unnormalised = z.cross(up);  // image right: view × up
  if (!(x_unnormalised.norm() > 1e-9 * up.norm()))
    throw InputError("camera pose", "the viewing direction must not be parallel to the up direction");
  const Eigen::Vector3d x = x_unnormalised.normalized();
  CameraPose pose;
  pose.rotation.row(0) = x.transpose();
  pose.rotation.row(1) = z.cross(x).transpose();  // image down
  pose.rotation.row(2) = z.transpose();
  pose.translation = -pose.rotation * centre;
  return pose;
}

std::vector<Eigen::Vector2d> ProjectApparatusPoints(const CameraIntrinsics& camera,
                                                    const CameraPose& pose,
                                                    const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> in_camera;
  in_camera.reserve(points.size());
  for (const auto& p : points) in_camera.push_back(pose.rotation * p + pose.translation);
  return ProjectCameraFramePoints(camera, in_camera);
}

std::vector<Eigen::Vector2d> UndistortPixels(const CameraIntrinsics& camera,
                                             const std::vector<Eigen::Vector2d>& raw) {
  if (raw.empty()) return {};
  std::vector<cv::Point2d> in;
  in.reserve(raw.size());
  for (const auto& p : raw) {
    if (!p.allFinite()) throw InputError("pixel", "must be finite");
    in.emplace_back(p.x(), p.y());
  }
  std::vector<cv::Point2d> out;
  // No rectification (R), and no new camera matrix (P): the output is normalised coordinates.
  cv::undistortPoints(in, out, CameraMatrix(camera), Distortion(camera), cv::noArray(), cv::noArray(),
                      kUndistortCriteria);
  std::vector<Eigen::Vector2d> result;
  result.reserve(out.size());
  for (const auto& q : out) result.emplace_back(q.x, q.y);
  return result;
}

Eigen::Vector2d UndistortPixel(const CameraIntrinsics& camera, const Eigen::Vector2d& raw) {
  return UndistortPixels(camera, {raw}).front();
}

Eigen::Vector3d CameraCentre(const CameraPose& pose) {
  return -pose.rotation.transpose() * pose.translation;
}

namespace {

json ParseJsonText(const std::string& path, const std::string& text) {
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path, std::string("is not valid JSON: ") + e.what());
  }
}

CameraIntrinsics CameraFromJson(const std::string& path, const json& j) {
  CheckFormat(j, path, kCameraFormat);
  return IntrinsicsFromJson(j, path, {"format", "calibration"});
}

SceneCalibration SceneFromJson(const std::string& path, const json& j);

// Longest point name kept (the page's names are short; a longer one is refused, not cut).
constexpr size_t kMaxPointNameBytes = 64;

SceneInputs InputsFromJson(const std::string& path, const json& j) {
  SceneInputs inputs;
  if (j.contains("points")) {
    const json& points = j.at("points");
    if (!points.is_array()) throw InputError(path + ".points", "must be an array of {name, u_px, v_px, x_m, y_m, z_m}");
    for (size_t i = 0; i < points.size(); ++i) {
      const std::string context = path + ".points[" + std::to_string(i) + "]";
      const json& p = points[i];
      CheckKeys(p, {"name", "u_px", "v_px", "x_m", "y_m", "z_m"}, context);
      const json& name = Member(p, "name", context);
      if (!name.is_string() || name.get<std::string>().empty() || name.get<std::string>().size() > kMaxPointNameBytes)
        throw InputError(context + ".name", "must be a text of 1 to " + std::to_string(kMaxPointNameBytes) + " bytes");
      ScenePoint point;
      point.label = name.get<std::string>();
      point.pixel = {Number(Member(p, "u_px", context), context + ".u_px"),
                     Number(Member(p, "v_px", context), context + ".v_px")};
      point.position = {Number(Member(p, "x_m", context), context + ".x_m"),
                        Number(Member(p, "y_m", context), context + ".y_m"),
                        Number(Member(p, "z_m", context), context + ".z_m")};
      inputs.points.push_back(point);
    }
  }
  if (j.contains("marks_m")) inputs.marks_x = Numbers(j.at("marks_m"), path + ".marks_m");
  if (j.contains("table_z_m")) inputs.table_z = Number(j.at("table_z_m"), path + ".table_z_m");
  return inputs;
}

void RequireFinite(double value, const std::string& context) {
  if (!std::isfinite(value)) throw InputError(context, "must be finite");
}

ordered_json InputsToJson(const SceneInputs& inputs) {
  ordered_json j = ordered_json::object();
  if (!inputs.points.empty()) {
    ordered_json points = ordered_json::array();
    for (size_t i = 0; i < inputs.points.size(); ++i) {
      const ScenePoint& p = inputs.points[i];
      const std::string context = "points[" + std::to_string(i) + "]";
      if (p.label.empty() || p.label.size() > kMaxPointNameBytes)
        throw InputError(context + ".name", "must be a text of 1 to " + std::to_string(kMaxPointNameBytes) + " bytes");
      if (!p.pixel.allFinite()) throw InputError(context + " (" + p.label + ")", "pixel must be finite");
      if (!p.position.allFinite()) throw InputError(context + " (" + p.label + ")", "position must be finite");
      points.push_back({{"name", p.label}, {"u_px", p.pixel.x()}, {"v_px", p.pixel.y()}, {"x_m", p.position.x()},
                        {"y_m", p.position.y()}, {"z_m", p.position.z()}});
    }
    j["points"] = points;
  }
  if (!inputs.marks_x.empty()) {
    for (double m : inputs.marks_x) RequireFinite(m, "marks");
    j["marks_m"] = inputs.marks_x;
  }
  if (inputs.table_z) {
    RequireFinite(*inputs.table_z, "table_z");
    j["table_z_m"] = *inputs.table_z;
  }
  return j;
}

}  // namespace

CameraIntrinsics ReadCameraFile(const std::string& path) { return CameraFromJson(path, ReadJsonFile(path)); }
CameraIntrinsics ParseCameraFile(const std::string& path, const std::string& text) {
  return CameraFromJson(path, ParseJsonText(path, text));
}
SceneCalibration ReadSceneFile(const std::string& path) { return SceneFromJson(path, ReadJsonFile(path)); }
SceneCalibration ParseSceneFile(const std::string& path, const std::string& text) {
  return SceneFromJson(path, ParseJsonText(path, text));
}
SceneInputs ReadSceneInputs(const std::string& path) {
  const json j = ReadJsonFile(path);
  SceneFromJson(path, j);
  return InputsFromJson(path, j);
}
SceneInputs ParseSceneInputs(const std::string& path, const std::string& text) {
  const json j = ParseJsonText(path, text);
  SceneFromJson(path, j);
  return InputsFromJson(path, j);
}

namespace {
SceneCalibration SceneFromJson(const std::string& path, const json& j) {
  CheckFormat(j, path, kSceneFormat);
  CheckKeys(j, {"format", "camera", "pose", "camera_centre_m", "viewing_direction", "calibration", "points", "marks_m",
               "table_z_m"},
            path);
  (void)InputsFromJson(path, j);  // a scene file with a malformed record of its inputs is refused as a whole
  SceneCalibration scene;
  scene.camera = IntrinsicsFromJson(Member(j, "camera", path), path + ".camera", {});
  const json& pose = Member(j, "pose", path);
  const std::string pose_context = path + ".pose";
  CheckKeys(pose, {"rotation", "translation_m"}, pose_context);
  const json& rotation = Member(pose, "rotation", pose_context);
  if (!rotation.is_array() || rotation.size() != 3)
    throw InputError(pose_context + ".rotation", "must be 3 rows of 3 numbers");
  for (int r = 0; r < 3; ++r) {
    const std::string row_context = pose_context + ".rotation[" + std::to_string(r) + "]";
    const std::vector<double> row = Numbers(rotation[r], row_context);
    if (row.size() != 3) throw InputError(row_context, "must hold 3 numbers");
    for (int c = 0; c < 3; ++c) scene.pose.rotation(r, c) = row[c];
  }
  ValidateRotation(scene.pose.rotation, pose_context + ".rotation");
  const std::vector<double> t =
      Numbers(Member(pose, "translation_m", pose_context), pose_context + ".translation_m");
  if (t.size() != 3) throw InputError(pose_context + ".translation_m", "must hold 3 numbers (metres)");
  scene.pose.translation = Eigen::Vector3d(t[0], t[1], t[2]);
  // camera_centre_m is derived from the pose, written for people; an edited copy that no longer
  // matches the pose would mislead whoever reads the file, so it is refused.
  if (j.contains("camera_centre_m")) {
    const std::vector<double> c = Numbers(j.at("camera_centre_m"), path + ".camera_centre_m");
    if (c.size() != 3 || (Eigen::Vector3d(c[0], c[1], c[2]) - CameraCentre(scene.pose)).norm() > 1e-6)
      throw InputError(path + ".camera_centre_m",
                       "does not match the pose (it is −rotationᵀ·translation_m; edit the pose, not this)");
  }
  return scene;
}
}  // namespace

std::string CameraFileText(const CameraIntrinsics& camera, const CalibrationSummary& summary) {
  ValidateIntrinsics(camera, "camera");
  ordered_json j{{"format", kCameraFormat}};
  j.update(IntrinsicsToJson(camera));
  j["calibration"] = SummaryToJson(summary);
  return j.dump(2) + "\n";
}

void WriteCameraFile(const std::string& path, const CameraIntrinsics& camera,
                     const CalibrationSummary& summary) {
  WriteFileAtomically(path, CameraFileText(camera, summary));
}

void WriteSceneFile(const std::string& path, const SceneCalibration& scene,
                    const CalibrationSummary& summary, const SceneInputs& inputs) {
  WriteFileAtomically(path, SceneFileText(scene, summary, inputs));
}

std::string SceneFileText(const SceneCalibration& scene, const CalibrationSummary& summary,
                          const SceneInputs& inputs) {
  ValidateIntrinsics(scene.camera, "camera");
  ValidateRotation(scene.pose.rotation, "pose.rotation");
  if (!scene.pose.translation.allFinite()) throw InputError("pose.translation", "must be finite");
  ordered_json rotation = ordered_json::array();
  for (int r = 0; r < 3; ++r)
    rotation.push_back({scene.pose.rotation(r, 0), scene.pose.rotation(r, 1), scene.pose.rotation(r, 2)});
  const Eigen::Vector3d& t = scene.pose.translation;
  const Eigen::Vector3d centre = CameraCentre(scene.pose);
  // The optical axis (camera z) in the apparatus frame: the third row of the rotation.
  const Eigen::Vector3d axis = scene.pose.rotation.row(2).transpose();
  ordered_json j{{"format", kSceneFormat},
         {"camera", IntrinsicsToJson(scene.camera)},
         {"pose", {{"rotation", rotation}, {"translation_m", {t.x(), t.y(), t.z()}}}},
         {"camera_centre_m", {centre.x(), centre.y(), centre.z()}},
         {"viewing_direction", {axis.x(), axis.y(), axis.z()}},
         {"calibration", SummaryToJson(summary)}};
  j.update(InputsToJson(inputs));
  return j.dump(2) + "\n";
}

}  // namespace uphill
