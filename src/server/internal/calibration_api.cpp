#include "calibration_api.hpp"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "app/scene_clicks.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "request_values.hpp"
#include "server/row_check.hpp"
#include "video_upload.hpp"
#include "vision/calibration.hpp"
#include "vision/camera.hpp"
#include "vision/decode_limits.hpp"
#include "vision/library_logs.hpp"

namespace uphill::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

const ContainedDirectory& FolderOf(const ExperimentStore& store) {
  const ContainedDirectory* folder = store.folder();
  if (!folder) throw InputError("experiment", "does not exist yet: create it first");
  return *folder;
}

double LengthIn(const json& j, const std::string& field, const std::string& unit) {
  if (!j.is_number()) throw InputError(field, "must be a number in " + unit);
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw InputError(field, "must be finite");
  return v * UnitFactor(Dimension::kLength, unit);
}

double InUnit(double si, const std::string& unit) { return ToUnit(si, Dimension::kLength, unit); }

constexpr std::size_t kMaxMarks = 20;  // marks on the rails a request may give

// The marks' distances along the rails (metres) from a list of numbers in `unit`.
std::vector<double> Marks(const json& list, const std::string& unit) {
  if (!list.is_array() || list.size() > kMaxMarks)
    throw InputError("marks", "must be a list of at most " + std::to_string(kMaxMarks) + " distances");
  std::vector<double> marks;
  for (const json& m : list) marks.push_back(LengthIn(m, "marks", unit));
  return marks;
}

const Row* RowOf(const StoreSnapshot& snapshot, const json& id) {
  if (id.is_null()) return nullptr;
  if (!id.is_number_integer()) throw InputError("row", "must be a row id");
  const int index = snapshot.state.IndexOf(id.get<std::int64_t>());
  if (index < 0) throw InputError("row", "row " + id.dump() + " does not exist");
  return &snapshot.state.rows[index];
}

CameraIntrinsics ExperimentCamera(const StoreSnapshot& snapshot) {
  const ordered_json& meta = snapshot.state.metadata;
  if (!meta.is_object() || !meta.contains("camera"))
    throw InputError("experiment.camera",
                     "no camera file yet: calibrate the camera first (section Camera: chessboard views), or put "
                     "the camera file of `uphill calibrate camera` in the folder and name it in experiment.json");
  const std::string path = meta.at("camera").get<std::string>();
  const auto it = snapshot.state.files.find(path);
  if (it == snapshot.state.files.end())
    throw InputError("experiment.camera", path + " is not in the experiment folder (or cannot be read)");
  return ParseCameraFile(path, it->second);
}

bool IsVideoName(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".mp4" || ext == ".avi" || ext == ".mkv" || ext == ".mov" || ext == ".m4v" || ext == ".webm";
}

bool IsImageName(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" || ext == ".tiff";
}

// The list body[key] of points {name, u, v, x, y, z} (u, v only `with_pixel`), lengths in `unit`.
std::vector<ScenePoint> PointList(const json& body, const std::string& key, bool with_pixel, const std::string& unit) {
  const json& list = body.value(key, json::array());
  if (!list.is_array() || list.size() > 100) throw InputError(key, "must be a list of at most 100 points");
  std::vector<ScenePoint> points;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& c = list[i];
    const std::string field = key + "[" + std::to_string(i) + "]";
    if (!c.is_object()) throw InputError(field, with_pixel ? "must be an object {name, u, v, x, y, z}" : "must be an object {name, x, y, z}");
    ScenePoint p;
    p.label = c.value("name", json("")).is_string() ? c.value("name", "") : "";
    if (p.label.empty()) p.label = "point " + std::to_string(i + 1);
    p.label = p.label.substr(0, 64);
    if (with_pixel) {
      for (const char* k : {"u", "v"})
        if (!c.contains(k) || !c.at(k).is_number() || !std::isfinite(c.at(k).get<double>()))
          throw InputError(field + "." + k, "must be a pixel coordinate (a number)");
      p.pixel = {c.at("u").get<double>(), c.at("v").get<double>()};
    }
    p.position = {LengthIn(c.value("x", json()), p.label + ": x", unit),
                  LengthIn(c.value("y", json()), p.label + ": y", unit),
                  LengthIn(c.value("z", json()), p.label + ": z", unit)};
    points.push_back(p);
  }
  return points;
}

}  // namespace

std::string FolderFile(const ExperimentStore& store, const std::string& relative, const std::string& field) {
  CheckRelativePath(relative, field);
  const ContainedDirectory& folder = FolderOf(store);
  const ContainedDirectory::Kind kind = KindInFolder(folder, relative, field);
  if (kind == ContainedDirectory::Kind::kAbsent)
    throw InputError(field, relative + " is not in the experiment folder");
  if (kind != ContainedDirectory::Kind::kFile)
    throw InputError(field, relative + " is not a regular file of the experiment folder (a link or a folder)");
  return (fs::path(folder.path()) / relative).string();
}

EncodedFrame VideoFrame(const ExperimentStore& store, const std::string& video, int frame, bool jpeg,
                        DecodeBudget& budget, std::chrono::milliseconds wait) {
  return ReadVideoFrame(FolderFile(store, video, "video"), video, frame, jpeg, &budget, wait);
}

ordered_json VideoInfo(const ExperimentStore& store, const std::string& video) {
  const VideoProbe probe = ProbeVideo(FolderFile(store, video, "video"), video);
  return {{"video", video}, {"width", probe.width}, {"height", probe.height}, {"fps", probe.fps}, {"frames", probe.frames}};
}

void CheckSceneFits(const StoreSnapshot& s, std::string scene, const std::string& video, const VideoProbe& probe) {
  const ordered_json& meta = s.state.metadata;
  if (!meta.is_object() || !meta.contains("scenes")) return;
  if (scene.empty() && meta.at("scenes").size() == 1) scene = meta.at("scenes").begin().key();
  if (scene.empty() || !meta.at("scenes").contains(scene)) return;
  const std::string path = meta.at("scenes").at(scene).get<std::string>();
  const auto it = s.state.files.find(path);
  if (it == s.state.files.end()) return;
  const SceneCalibration calibration = ParseSceneFile(path, it->second);
  if (calibration.camera.width != probe.width || calibration.camera.height != probe.height)
    throw InputError("video", video + " is " + std::to_string(probe.width) + "×" + std::to_string(probe.height) +
                                " px but the scene file " + path + " (scene \"" + scene + "\") is for " +
                                std::to_string(calibration.camera.width) + "×" +
                                std::to_string(calibration.camera.height) +
                                " px: calibrate a scene for this video's camera setting");
}

ordered_json ListVideos(const ExperimentStore& store) {
  ordered_json videos = ordered_json::array();
  const ContainedDirectory* folder = store.folder();
  if (!folder) return {{"videos", videos}};
  const fs::path root(folder->path());
  std::vector<std::pair<std::string, std::uintmax_t>> found;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!name.empty() && name[0] == '.') {  // staging folders, caches, hidden files
      if (it->is_directory(ec)) it.disable_recursion_pending();
      continue;
    }
    if (it.depth() >= 3) it.disable_recursion_pending();
    if (it->is_symlink(ec) || !it->is_regular_file(ec) || !IsVideoName(name)) continue;
    found.emplace_back(fs::relative(it->path(), root).generic_string(), it->file_size(ec));
    if (found.size() >= 1000) break;
  }
  std::sort(found.begin(), found.end());
  for (const auto& [path, bytes] : found) videos.push_back({{"path", path}, {"bytes", bytes}});
  return {{"videos", videos}};
}

ordered_json ScenePoints(const StoreSnapshot& snapshot, const json& query) {
  const std::string& unit = snapshot.state.unit;
  const Row* row = RowOf(snapshot, query.value("row", json()));
  const double table_z = query.contains("table_z") ? LengthIn(query.at("table_z"), "table_z", unit) : 0.0;
  std::vector<double> marks;
  if (query.contains("marks")) {
    marks = Marks(query.at("marks"), unit);
  }
  std::vector<ApparatusPoint> points;
  std::string note;
  if (row) {
    try {
      points = SettingCalibrationPoints(RowConfiguration(snapshot.state, *row), table_z, marks);
    } catch (const InputError& e) {
      if (e.quantity() == "marks") throw;  // the request's own marks: refused, not left out
      note = std::string("only O: ") + e.what();
    }
  } else {
    note = "only O: pick a trial to offer the points of its setting (L, H, D)";
  }
  if (points.empty()) points.push_back({"O", Eigen::Vector3d::Zero()});
  ordered_json out = ordered_json::array();
  for (const ApparatusPoint& p : points)
    out.push_back({{"name", p.name},
                   {"x", InUnit(p.position.x(), unit)},
                   {"y", InUnit(p.position.y(), unit)},
                   {"z", InUnit(p.position.z(), unit)}});
  return {{"points", out}, {"unit", unit}, {"note", note}};
}

ordered_json SolveScene(const ExperimentStore& store, const StoreSnapshot& snapshot, const json& body,
                        std::string* scene_file) {
  const std::string& unit = snapshot.state.unit;
  if (!body.contains("video") || !body.at("video").is_string()) throw InputError("video", "is missing");
  const std::string video = body.at("video").get<std::string>();
  const VideoProbe probe = ProbeVideo(FolderFile(store, video, "video"), video);
  const CameraIntrinsics camera = ExperimentCamera(snapshot);
  SceneClicks request;
  request.clicks = PointList(body, "clicks", true, unit);
  if (body.contains("unclicked"))
    for (const ScenePoint& p : PointList(body, "unclicked", false, unit)) request.unclicked.push_back({p.label, p.position});
  if (body.contains("marks")) request.marks_x = Marks(body.at("marks"), unit);
  if (body.contains("table_z")) request.table_z = LengthIn(body.at("table_z"), "table_z", unit);
  const std::vector<ScenePoint>& points = request.clicks;
  std::optional<Scene> scene;
  if (const Row* row = RowOf(snapshot, body.value("row", json()))) {
    try {
      scene = RowConfiguration(snapshot.state, *row).MakeScene();
    } catch (const InputError&) {
      // No path to draw; the pose is still solved.
    }
  }
  SceneClicksSolution s;
  try {
    s = SolveSceneClicks(camera, request, probe.width, probe.height, scene);
  } catch (const InputError& e) {
    if (e.quantity() == "frame")
      throw InputError("video", video + " is " + std::to_string(probe.width) + "×" + std::to_string(probe.height) +
                                    " px but the experiment's camera file is for " + std::to_string(camera.width) +
                                    "×" + std::to_string(camera.height) +
                                    " px: calibrate the camera at the video's resolution");
    if (e.quantity() == "points") throw InputError("clicks", e.rule());
    throw;
  }
  ordered_json out_points = ordered_json::array();
  for (std::size_t i = 0; i < points.size(); ++i)
    out_points.push_back({{"name", points[i].label},
                          {"u", points[i].pixel.x()},
                          {"v", points[i].pixel.y()},
                          {"u_model", s.reprojected[i].x()},
                          {"v_model", s.reprojected[i].y()},
                          {"residual_px", s.calibration.residuals[i].error_px}});
  ordered_json path = ordered_json::array();
  for (const Eigen::Vector2d& p : s.centre_path) path.push_back({p.x(), p.y()});
  const Eigen::Vector3d centre = CameraCentre(s.calibration.scene.pose);
  if (scene_file) *scene_file = s.scene_file;
  ordered_json leave_one_out = nullptr;
  if (const auto& check = s.calibration.leave_one_out)
    leave_one_out = {{"name", check->label},
                     {"residual_px", check->residual_px},
                     {"rms_without_px", check->rms_without_px},
                     {"explains", check->explains}};
  const auto pixels = [](const std::vector<ApparatusPoint>& list) {
    ordered_json out = ordered_json::array();
    for (const ApparatusPoint& p : list) out.push_back({{"name", p.name}, {"u", p.pixel.x()}, {"v", p.pixel.y()}});
    return out;
  };
  return {{"rms_px", s.calibration.rms_px},
          {"verdict", s.calibration.verdict},
          {"reasons", s.calibration.reasons},
          {"leave_one_out", leave_one_out},
          {"points", out_points},
          {"expected", pixels(s.expected)},
          {"axes", pixels(s.axes)},
          {"path", path},
          {"camera_centre", {{"x", InUnit(centre.x(), unit)}, {"y", InUnit(centre.y(), unit)}, {"z", InUnit(centre.z(), unit)}}},
          {"unit", unit}};
}

ImageSize ProbeImage(const std::string& path, const std::string& name) {
  const std::string not_image =
      "not an image OpenCV can decode (a chessboard view must be a PNG, JPEG, BMP or TIFF photo or frame); nothing "
      "was kept";
  const std::optional<PixelSize> size = ImageHeaderSize(path);  // its size, before decoding it
  if (!size) throw InputError(name, not_image);
  CheckPixelCount(size->width, size->height, name, "an image");
  QuietVideoLibraryLogs();  // a refused file is said once, in the answer
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(name, not_image);
  return {image.cols, image.rows};
}

ordered_json SavedScene(const StoreSnapshot& snapshot, const std::string& name) {
  SceneFilePath(name);  // the name's rule
  const std::string& unit = snapshot.state.unit;
  const ordered_json& meta = snapshot.state.metadata;
  if (!meta.is_object() || !meta.contains("scenes") || !meta.at("scenes").contains(name))
    throw InputError("name", "the experiment has no scene \"" + name + "\"");
  const std::string path = meta.at("scenes").at(name).get<std::string>();
  const auto it = snapshot.state.files.find(path);
  if (it == snapshot.state.files.end())
    throw InputError("name", "the scene file " + path + " is not in the experiment folder (or cannot be read)");
  const SceneInputs inputs = ParseSceneInputs(path, it->second);
  ordered_json points = ordered_json::array();
  for (const ScenePoint& p : inputs.points)
    points.push_back({{"name", p.label},
                      {"u", p.pixel.x()},
                      {"v", p.pixel.y()},
                      {"x", InUnit(p.position.x(), unit)},
                      {"y", InUnit(p.position.y(), unit)},
                      {"z", InUnit(p.position.z(), unit)}});
  ordered_json marks = ordered_json::array();
  for (double m : inputs.marks_x) marks.push_back(InUnit(m, unit));
  return {{"name", name},
          {"path", path},
          {"points", points},
          {"marks", marks},
          {"table_z", inputs.table_z ? ordered_json(InUnit(*inputs.table_z, unit)) : ordered_json(nullptr)},
          {"unit", unit}};
}

std::string SceneFilePath(const std::string& name) {
  static const std::regex ok("[A-Za-z0-9_-]{1,32}");
  if (!std::regex_match(name, ok)) throw InputError("name", "a scene's name is 1 to 32 letters, digits, '-' or '_'");
  return "calibration/scene-" + name + ".json";
}

ordered_json CalibrateCameraViews(const ExperimentStore& store, const StoreSnapshot& snapshot, const json& body,
                                  std::string* camera_file) {
  const std::string& unit = snapshot.state.unit;
  if (!body.contains("folder") || !body.at("folder").is_string()) throw InputError("folder", "is missing");
  const std::string folder_name = body.at("folder").get<std::string>();
  CheckRelativePath(folder_name, "folder");
  const ContainedDirectory& folder = FolderOf(store);
  if (KindInFolder(folder, folder_name, "folder") != ContainedDirectory::Kind::kDirectory)
    throw InputError("folder", folder_name + " is not a folder of the experiment");
  const ContainedDirectory views = folder.Subdirectory(folder_name, false);
  std::vector<std::string> paths;
  for (const std::string& name : views.RegularFiles())
    if (IsImageName(name)) paths.push_back((fs::path(views.path()) / name).string());
  if (paths.empty()) throw InputError("folder", folder_name + " holds no images (.png, .jpg, .bmp, .tif)");
  if (paths.size() > 60) throw InputError("folder", folder_name + " holds more than 60 images: keep 10 to 20 views");
  ChessboardTarget target;
  for (const char* k : {"cols", "rows"})
    if (body.contains(k))
      (std::string(k) == "cols" ? target.cols : target.rows) =
          static_cast<int>(WholeNumberJson(body.at(k), k, 2, 100, "the count of inner corners"));
  if (body.contains("square")) target.square = LengthIn(body.at("square"), "square", unit);
  ValidateCalibrationTarget(target, "square");
  CameraCalibration c;
  try {
    c = CalibrateCameraFromFiles(paths, target);
  } catch (const InputError& e) {
    const std::string root = folder.path() + "/";
    std::string message = e.what();
    for (std::size_t at; (at = message.find(root)) != std::string::npos;) message.erase(at, root.size());
    throw InputError("folder", message);
  }
  *camera_file = CameraFileText(c.camera, c.Summary(target));
  ordered_json view_list = ordered_json::array();
  for (const ViewDiagnostics& v : c.views)
    view_list.push_back({{"name", fs::path(v.name).filename().string()},
                         {"used", v.used},
                         {"rejected_because", v.rejected_because},
                         {"rms_px", v.rms_px},
                         {"tilt_deg", v.tilt_deg}});
  return {{"verdict", c.verdict},     {"reasons", c.reasons}, {"rms_px", c.rms_px},   {"views_used", c.views_used},
          {"coverage", c.coverage},   {"fx", c.camera.fx},    {"fy", c.camera.fy},    {"cx", c.camera.cx},
          {"cy", c.camera.cy},        {"width", c.camera.width}, {"height", c.camera.height}, {"views", view_list}};
}

}  // namespace uphill::internal
