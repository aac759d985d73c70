#include "footage/footage_clip.hpp"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>
#include <atomic>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/json_file.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "internal/content_key.hpp"
#include "footage/lens_remap.hpp"
#include "internal/footage_renderer.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2d;
using Eigen::Vector3d;
using ordered_json = nlohmann::ordered_json;
using internal::FootageRenderer;
using internal::PovrayWork;

// A digest of the generator's code (src/footage/CMakeLists.txt): what the same condition's pixels
// and truth are depends on it, so it is part of every cache key.
constexpr const char* kGeneratorDigest = UPHILL_FOOTAGE_GENERATOR_DIGEST;
constexpr double kInf = std::numeric_limits<double>::infinity();

ordered_json DescribeCamera(const CameraIntrinsics& c) {
  return {{"width_px", c.width}, {"height_px", c.height}, {"fx_px", c.fx}, {"fy_px", c.fy},
          {"cx_px", c.cx},       {"cy_px", c.cy},         {"distortion", c.distortion}};
}

ordered_json DescribePose(const CameraPose& p) {
  std::vector<double> r(p.rotation.data(), p.rotation.data() + 9);
  return {{"rotation_colmajor", r}, {"translation_m", {p.translation.x(), p.translation.y(), p.translation.z()}}};
}

ordered_json DescribeSensor(const SensorModel& s, double gain, double vignetting) {
  return {{"full_well_e", s.full_well}, {"read_noise_e", s.read_noise}, {"seed", s.seed},
          {"noise", s.noise},           {"gain", gain},                 {"vignetting", vignetting}};
}

ordered_json DescribeBoards(const FootageCondition& c) {
  return {{"generator", kGeneratorDigest},
          {"camera", DescribeCamera(c.camera.camera)},
          {"sensor", DescribeSensor(c.sensor, c.gain, c.vignetting)},
          {"boards", c.boards},
          {"target", {{"cols", c.board_target.cols}, {"rows", c.board_target.rows}, {"square_m", c.board_target.square}}},
          {"povray", {{"aa", c.povray.antialias_threshold}, {"depth", c.povray.antialias_depth}}}};
}

// Smallest t > 0 at which the ray o + t·d (d unit) meets the cylinder of radius r about the
// segment p0 + s·e, s ∈ [0, length] (e unit); ∞ if none.

void Validate(const FootageCondition& c) {
  ValidateIntrinsics(c.camera.camera, "camera");
  if (c.frames < 1) throw InputError("frames", "must be >= 1");
  if (!(c.shutter.fps > 0 && std::isfinite(c.shutter.fps))) throw InputError("fps", "must be > 0");
  if (!(c.shutter.exposure > 0 && c.shutter.exposure <= 1 / c.shutter.fps * (1 + 1e-12)))
    throw InputError("exposure", "must be in (0, 1/fps] (a shutter angle of at most 360 degrees)");
  if (!(c.shutter.readout >= 0 && c.shutter.readout <= 1 / c.shutter.fps))
    throw InputError("readout", "must be in [0, 1/fps]");
  if (c.events.exposure_changes_at >= 0 &&
      !(c.events.changed_exposure > 0 && c.events.changed_exposure <= 1 / c.shutter.fps * (1 + 1e-12)))
    throw InputError("changed exposure", "must be in (0, 1/fps]");
  if (!(c.max_step_px > 0)) throw InputError("max_step_px", "must be > 0");
  if (!(c.gain > 0) || !(c.sensor.full_well > 0) || !(c.sensor.read_noise >= 0))
    throw InputError("sensor", "gain and full well must be > 0, read noise >= 0");
  if (c.boards < 0) throw InputError("boards", "must be >= 0");
}

std::string FileName(const char* pattern, int k) {
  char name[64];
  std::snprintf(name, sizeof name, pattern, k);
  return name;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error(path.string() + ": cannot encode PNG");
  WriteFileAtomically(path.string(), std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

double ProcessCpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Renders the chessboard views of the condition's camera into `folder` (shared by all clips of
// that camera and sensor), unless they are there.
std::vector<std::string> EnsureBoards(const FootageCondition& c, const fs::path& root, FootageRenderer& renderer,
                                      const FootageProgress& progress) {
  const fs::path folder = root / ("boards-" + internal::ContentKey(DescribeBoards(c).dump()));
  std::vector<std::string> paths;
  for (int k = 0; k < c.boards; ++k) paths.push_back((folder / FileName("board_%02d.png", k)).string());
  if (fs::exists(folder / "complete")) return paths;
  fs::create_directories(folder);
  const std::vector<CameraPose> poses = RandomBoardPoses(c.camera.camera, c.board_target, c.boards, 7);
  std::vector<BoardInView> boards;
  for (const CameraPose& pose : poses) boards.push_back({c.board_target, pose, 1.0});
  if (progress.report) progress.report("chessboard views", 0, c.boards);
  const std::vector<cv::Mat> pictures = renderer.RenderBoards(boards);
  for (int k = 0; k < c.boards; ++k) {
    std::vector<cv::Mat> channels(3);
    cv::split(pictures[k], channels);
    for (cv::Mat& ch : channels) ch = ch.mul(renderer.vignetting(), c.gain);
    cv::Mat lit;
    cv::merge(channels, lit);
    WritePng(paths[k], c.sensor.ToFrame8(lit, 1000000 + k));
  }
  WriteFileAtomically((folder / "complete").string(), DescribeBoards(c).dump(2) + "\n");
  return paths;
}

}  // namespace

ordered_json DescribeFootage(const FootageCondition& c) {
  const Body& body = c.scene.body();
  ordered_json j;
  j["generator"] = kGeneratorDigest;
  j["name"] = c.name;
  j["body"] = {{"kind", body.kind == BodyKind::kSphere ? "sphere" : "spheroid"},
               {"across_m", body.across},
               {"along_m", body.along}};
  j["rails"] = {{"tan_theta", c.scene.rails().tan_theta},
                {"tan_half_alpha", c.scene.rails().tan_half_alpha},
                {"rod_radius_m", c.scene.rod_radius()}};
  const FootageApparatus& a = c.apparatus;
  j["apparatus"] = {{"crossbar_x_m", a.crossbar_x}, {"crossbar_radius_m", a.crossbar_radius},
                    {"post_radius_m", a.post_radius}, {"rail_overhang_m", a.rail_overhang},
                    {"table_z_m", a.table_z},        {"wall_y_m", a.wall_y},
                    {"marks_m", a.marks}};
  const auto rgb = [](const Eigen::Vector3d& v) { return ordered_json::array({v.x(), v.y(), v.z()}); };
  static const char* const kTables[] = {"wood", "cloth", "paper", "tiles"};
  static const char* const kFinishes[] = {"satin", "matte", "glossy", "chrome"};
  static const char* const kPatterns[] = {"plain", "two-tone", "stripes", "dots"};
  ordered_json lamps = ordered_json::array();
  for (const FootageLamp& lamp : c.look.lamps)
    lamps.push_back({{"position_m", rgb(lamp.position)}, {"intensity", lamp.intensity}});
  j["look"] = {{"table", kTables[static_cast<int>(c.look.table)]},
               {"body_rgb", rgb(c.look.body_rgb)},
               {"band_rgb", rgb(c.look.band_rgb)},
               {"band_half_width_m", c.look.band_half_width},
               {"light", c.look.light},
               {"finish", kFinishes[static_cast<int>(c.look.finish)]},
               {"pattern", kPatterns[static_cast<int>(c.look.pattern)]},
               {"pattern_scale_m", c.look.pattern_scale},
               {"pattern_turn_deg", rgb(c.look.pattern_turn)},
               {"rod_rgb", c.look.rod_rgb ? rgb(*c.look.rod_rgb) : ordered_json()},
               {"lamps", lamps}};
  j["camera"] = DescribeCamera(c.camera.camera);
  j["pose"] = DescribePose(c.camera.pose);
  j["motion"] = {{"x0_m", c.x0},
                 {"release_time_s", c.release_time},
                 {"v0_m_per_s", c.motion.v0},
                 {"g_m_per_s2", c.motion.g},
                 {"mu", c.motion.mu},
                 {"ode", c.motion.method == MotionMethod::kOde},
                 {"tolerance", c.motion.tolerance}};
  j["frames"] = c.frames;
  j["shutter"] = {{"fps", c.shutter.fps}, {"exposure_s", c.shutter.exposure}, {"readout_s", c.shutter.readout},
                  {"t0_s", c.shutter.t0}};
  j["light"] = {{"flicker_depth", c.light.flicker_depth}, {"flicker_hz", c.light.flicker_hz},
                {"flicker_phase", c.light.flicker_phase}, {"drift_depth", c.light.drift_depth},
                {"drift_period_s", c.light.drift_period}, {"drift_phase", c.light.drift_phase}};
  j["sensor"] = DescribeSensor(c.sensor, c.gain, c.vignetting);
  j["codec"] = CodecName(c.codec);
  j["bit_rate"] = c.bit_rate;
  j["max_step_px"] = c.max_step_px;
  j["max_subframes"] = c.max_subframes;
  j["events"] = {{"body_never_visible", c.events.body_never_visible},
                 {"camera_moves_at", c.events.camera_moves_at},
                 {"moved_pose", DescribePose(c.events.moved_pose)},
                 {"exposure_changes_at", c.events.exposure_changes_at},
                 {"changed_exposure_s", c.events.changed_exposure},
                 {"changed_gain", c.events.changed_gain}};
  j["boards"] = DescribeBoards(c);
  return j;
}

std::string FootageKey(const FootageCondition& c) { return internal::ContentKey(DescribeFootage(c).dump()); }

std::string FootageCacheRoot() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  fs::path base;
  if (xdg && *xdg) base = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home) base = fs::path(home) / ".cache";
  else base = fs::temp_directory_path();
  return (base / "uphill" / "clips").string();
}

std::vector<ApparatusPoint> FootageApparatusPoints(const FootageCondition& c) {
  return VisibleApparatusPoints(c.camera.camera, c.camera.pose,
                                ApparatusCalibrationPoints(c.scene.rails(), c.apparatus.crossbar_x, c.apparatus.table_z,
                                                           c.apparatus.marks));
}

FootageWork PlanFootage(const FootageCondition& condition, const std::string& cache_root) {
  Validate(condition);
  const fs::path root = fs::absolute(cache_root);
  FootageWork work;
  work.clip_cached = fs::exists(root / FootageKey(condition) / "condition.json");
  work.boards_cached =
      condition.boards == 0 ||
      fs::exists(root / ("boards-" + internal::ContentKey(DescribeBoards(condition).dump())) / "complete");
  FootageRenderer renderer(condition, fs::path(), root / "pictures");
  for (const auto& job : renderer.StaticJobs()) {
    const PovrayWork w = renderer.Work(job);
    work.static_pictures += 1;
    work.static_to_render += !w.cached;
    work.static_pixels_to_render += w.cached ? 0 : w.pixels;
  }
  // All frames in one batch, so that a resting body's picture is shared as RenderFootage shares it.
  std::vector<FootageRenderer::FramePlan> plans;
  for (int f = 0; f < condition.frames; ++f) plans.push_back(renderer.Plan(f));
  auto batch = renderer.Jobs(plans);
  std::map<const void*, int> frame_of;  // region -> index of its frame
  for (size_t i = 0; i < plans.size(); ++i) {
    work.frames.push_back({plans[i].frame});
    for (const auto& region : plans[i].regions) frame_of[&region] = static_cast<int>(i);
  }
  for (size_t j = 0; j < batch.jobs.size(); ++j) {
    const PovrayWork w = renderer.Work(batch.jobs[j]);
    FootageFrameWork& frame = work.frames[frame_of.at(batch.parts[j].region)];
    frame.subframes += w.subframes;
    work.subframes += w.subframes;
    if (w.cached) continue;
    frame.subframes_to_render += w.subframes;
    frame.pixels_to_render += w.pixels;
    work.runs_to_render += 1;
    work.subframes_to_render += w.subframes;
    work.pixels_to_render += w.pixels;
  }
  return work;
}

FootageFiles RenderFootage(const FootageCondition& condition, const std::string& cache_root, bool fresh,
                           const FootageProgress& progress) {
  Validate(condition);
  const fs::path root = fs::absolute(cache_root);
  const fs::path folder = root / FootageKey(condition);
  const std::string ext = condition.codec == VideoCodec::kFfv1 ? ".mkv" : ".mp4";
  FootageFiles files;
  files.folder = folder.string();
  files.video = (folder / ("clip" + ext)).string();
  files.truth_csv = (folder / "truth.csv").string();
  files.points_csv = (folder / "points.csv").string();
  files.first_frame = (folder / "frame0.png").string();
  files.camera_truth = (folder / "camera_truth.json").string();
  files.scene_truth = (folder / "scene_truth.json").string();
  const fs::path boards_marker = root / ("boards-" + internal::ContentKey(DescribeBoards(condition).dump())) / "complete";
  if (!fresh && fs::exists(folder / "condition.json") && (condition.boards == 0 || fs::exists(boards_marker))) {
    const nlohmann::json saved = ReadJsonFile((folder / "condition.json").string());
    files.from_cache = true;
    files.render_wall_seconds = saved.value("render_wall_s", 0.0);
    files.render_cpu_seconds = saved.value("render_cpu_s", 0.0);
    files.povray_runs = saved.value("povray_runs", 0);
    files.subframes = saved.value("subframes", 0);
    for (int k = 0; k < condition.boards; ++k)
      files.boards.push_back((boards_marker.parent_path() / FileName("board_%02d.png", k)).string());
    return files;
  }
  const auto start = std::chrono::steady_clock::now();
  const double cpu0 = ProcessCpuSeconds();
  // Render into a private folder, then rename it into place: a folder under its key is complete.
  const fs::path partial = root / (FootageKey(condition) + ".partial-" + std::to_string(getpid()));
  fs::remove_all(partial);
  fs::create_directories(partial);
  FootageRenderer renderer(condition, partial, fresh ? fs::path() : root / "pictures");
  files.boards = EnsureBoards(condition, root, renderer, progress);
  if (progress.report) progress.report("static scene", 0, condition.frames);
  renderer.RenderStatic();
  VideoEncoderSettings enc;
  enc.codec = condition.codec;
  enc.fps = condition.shutter.fps;
  enc.bit_rate = condition.bit_rate;
  const CameraIntrinsics& k = condition.camera.camera;
  VideoEncoder encoder((partial / ("clip" + ext)).string(), cv::Size(k.width, k.height), enc);
  std::vector<ClipTruth> truth;
  // Frames in batches: their sub-frames render together (the pool stays busy), then compose.
  constexpr int kBatch = 8;
  for (int first = 0; first < condition.frames; first += kBatch) {
    if (progress.report) progress.report("frames", first, condition.frames);
    std::vector<FootageRenderer::FramePlan> plans;
    for (int f = first; f < std::min(condition.frames, first + kBatch); ++f) plans.push_back(renderer.Plan(f));
    renderer.Render(plans);
    for (const FootageRenderer::FramePlan& plan : plans) {
      cv::Mat linear = renderer.Compose(plan);
      std::vector<cv::Mat> channels(3);
      cv::split(linear, channels);
      for (cv::Mat& ch : channels) ch = ch.mul(renderer.vignetting(), renderer.Gain(plan.frame));
      cv::merge(channels, linear);
      const cv::Mat frame = condition.sensor.ToFrame8(linear, static_cast<std::uint64_t>(plan.frame));
      if (plan.frame == 0) WritePng(partial / "frame0.png", frame);
      encoder.Write(frame);
      truth.push_back(plan.truth);
    }
  }
  encoder.Finish();
  WriteClipTruthCsv((partial / "truth.csv").string(), truth);
  std::ostringstream points;
  points << "name,u,v,x_mm,y_mm,z_mm\n";
  for (const ApparatusPoint& p : FootageApparatusPoints(condition)) {
    char line[200];
    std::snprintf(line, sizeof line, "%s,%.4f,%.4f,%.4f,%.4f,%.4f\n", p.name.c_str(), p.pixel.x(), p.pixel.y(),
                  p.position.x() * 1e3, p.position.y() * 1e3, p.position.z() * 1e3);
    points << line;
  }
  WriteFileAtomically((partial / "points.csv").string(), points.str());
  CalibrationSummary summary;
  summary.method = "the true camera of the POV-Ray footage (src/footage/footage_clip.hpp)";
  summary.verdict = "exact";
  summary.reasons = {"the camera that rendered the clip: no calibration error"};
  WriteCameraFile((partial / "camera_truth.json").string(), k, summary);
  WriteSceneFile((partial / "scene_truth.json").string(), condition.camera, summary);
  for (const fs::directory_entry& e : fs::directory_iterator(partial))
    if (e.is_directory() && e.path().filename().string().rfind("povray-", 0) == 0) fs::remove_all(e.path());
  files.render_wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  files.render_cpu_seconds = ProcessCpuSeconds() - cpu0 + renderer.povray_cpu;
  files.povray_runs = renderer.povray_runs;
  files.subframes = renderer.subframes;
  ordered_json description = DescribeFootage(condition);
  description["render_wall_s"] = files.render_wall_seconds;
  description["render_cpu_s"] = files.render_cpu_seconds;
  description["povray_runs"] = files.povray_runs;
  description["subframes"] = files.subframes;
  WriteFileAtomically((partial / "condition.json").string(), description.dump(2) + "\n");
  std::error_code ec;
  fs::remove_all(folder, ec);
  fs::rename(partial, folder);
  return files;
}

std::vector<ClipTruth> ReadFootageTruth(const std::string& path) {
  const CsvTable table = ReadCsvFile(path);
  const char* names[] = {"frame", "t", "x", "z", "u", "v", "visibility"};
  int col[7];
  for (int i = 0; i < 7; ++i) {
    col[i] = table.Column(names[i]);
    if (col[i] < 0) throw InputError(path, std::string("has no column ") + names[i]);
  }
  std::vector<ClipTruth> out;
  for (const CsvRow& row : table.rows) {
    if (!row.error.empty()) throw InputError(path + ", row " + std::to_string(row.row), row.error);
    auto number = [&](int i) {
      const std::string context = CellContext(table, row.row, names[i]);
      return ParseQuantity(row.cells[col[i]], Dimension::kDimensionless, context);
    };
    ClipTruth t;
    t.frame = static_cast<int>(number(0));
    t.t = number(1);
    t.present = !row.cells[col[2]].empty();
    if (t.present) {
      t.x = number(2) * 1e-3, t.z = number(3) * 1e-3, t.u = number(4), t.v = number(5);
      t.visibility = number(6);
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace uphill
