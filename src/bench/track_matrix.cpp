#include "bench/track_matrix.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include <opencv2/videoio.hpp>

#include "bench/support.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "model/input_error.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/calibration.hpp"
#include "footage/footage_conditions.hpp"
#include "vision/video_tracking.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2d;
using Eigen::Vector3d;

const std::vector<std::string> kPeers = {"CSRT", "KCF", "HoughCircles"};

std::string Fixed(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// A method's position in one frame: raw pixel, and (x, z) in m.
struct Position {
  bool found = false;
  double u = 0, v = 0, x = 0, z = 0;
  bool full_model = false;
};

// TrackMatrixOptions::positions: one clip's frames, tracked and true, side by side.
void WritePositions(const std::string& path, const std::vector<ClipTruth>& truth,
                    const std::vector<Position>& found) {
  std::string text = "frame,found,full_model,u,v,x_mm,z_mm,u_true,v_true,x_true_mm,z_true_mm,visibility\n";
  for (size_t i = 0; i < truth.size(); ++i) {
    const ClipTruth& t = truth[i];
    const Position p = i < found.size() ? found[i] : Position{};
    const auto number = [&](double v) { return p.found ? Fixed("%.4f", v) : std::string(); };
    text += std::to_string(t.frame) + "," + (p.found ? "1," : "0,") + (p.full_model ? "1," : "0,") + number(p.u) +
            "," + number(p.v) + "," + number(p.x * 1e3) + "," + number(p.z * 1e3) + "," +
            (t.present ? Fixed("%.4f", t.u) + "," + Fixed("%.4f", t.v) + "," + Fixed("%.4f", t.x * 1e3) + "," +
                             Fixed("%.4f", t.z * 1e3)
                       : std::string(",,,")) +
            "," + Fixed("%.3f", t.visibility) + "\n";
  }
  WriteFileAtomically(path, text);
}

struct Score {
  double rms_px = NAN, rms_mm = NAN;
  int found = 0;       // of the comparable frames
  int comparable = 0;  // body present, at least half visible
  int found_any = 0;   // frames with a reported position
  int invented = 0;    // positions reported where there is no body in the picture
};

Score Compare(const std::vector<ClipTruth>& truth, const std::vector<Position>& found) {
  Score s;
  double px = 0, mm = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const ClipTruth& t = truth[i];
    const bool has = i < found.size() && found[i].found;
    s.found_any += has;
    s.invented += has && !(t.present && t.visibility > 0);
    if (!t.present || t.visibility < 0.5) continue;
    ++s.comparable;
    if (!has) continue;
    ++s.found;
    const Position& p = found[i];
    px += (p.u - t.u) * (p.u - t.u) + (p.v - t.v) * (p.v - t.v);
    mm += ((p.x - t.x) * (p.x - t.x) + (p.z - t.z) * (p.z - t.z)) * 1e6;
  }
  if (s.found > 0) s.rms_px = std::sqrt(px / s.found), s.rms_mm = std::sqrt(mm / s.found);
  return s;
}

// Where the calibrated viewing ray of a raw pixel meets the plane y = 0 (the body's centre plane).
bool RayOnCentrePlane(const SceneCalibration& cal, const Vector2d& pixel, double* x, double* z) {
  const Vector2d n = UndistortPixel(cal.camera, pixel);
  const Vector3d eye = CameraCentre(cal.pose);
  const Vector3d d = cal.pose.rotation.transpose() * Vector3d(n.x(), n.y(), 1);
  if (std::abs(d.y()) < 1e-12) return false;
  const double s = -eye.y() / d.y();
  if (!(s > 0)) return false;
  *x = eye.x() + s * d.x();
  *z = eye.z() + s * d.z();
  return true;
}

std::vector<Position> ReadPeerPositions(const std::string& path, const SceneCalibration& cal) {
  std::vector<Position> out;
  if (!fs::exists(path)) return out;
  const CsvTable table = ReadCsvFile(path);
  const int cu = table.Column("u"), cv = table.Column("v");
  for (const CsvRow& row : table.rows) {
    Position p;
    if (row.error.empty() && cu >= 0 && cv >= 0 && !row.cells[cu].empty()) {
      p.u = std::stod(row.cells[cu]);
      p.v = std::stod(row.cells[cv]);
      p.found = std::isfinite(p.u) && std::isfinite(p.v) && RayOnCentrePlane(cal, Vector2d(p.u, p.v), &p.x, &p.z);
    }
    out.push_back(p);
  }
  return out;
}

std::string Cell(const Score& s, bool px) {
  if (s.found == 0) return "-";
  return px ? Fixed("%.3f", s.rms_px) : Fixed("%.3f", s.rms_mm);
}

std::string Found(const Score& s) { return std::to_string(s.found) + "/" + std::to_string(s.comparable); }

std::string RenderTime(const FootageFiles& f) {
  return Fixed("%.0f s", f.render_wall_seconds) + Fixed(" (%.0f)", f.render_cpu_seconds);
}

// Runs of the tracker and of decoding alone per clip, the best of which is timed.
constexpr int kTimingRounds = 3;

struct Run {
  NamedFootage named;
  FootageFiles files;
  std::vector<ClipTruth> truth;
  SceneCalibration calibrated;  // the user's path: calibrate camera + calibrate scene
  std::string calibration_note;
  Score uphill;
  std::string uphill_says;  // error / partial / complete
  double ms_per_frame = 0;         // the tracker alone with its set-up and end (its thread's CPU time)
  double decode_ms_per_frame = 0;  // VideoCapture::read alone (process CPU time)
  double model_share = 0;          // frames measured by the full model, of those found
  std::map<std::string, Score> peers;
};

}  // namespace

const char* const kTrackMatrixMethod =
    "Robustness: ray-traced clips (POV-Ray, src/footage/footage_conditions.hpp) that differ from a baseline in one "
    "respect each: contrast only in colour, wood or cloth, 8 mm rods or 1 mm wires, the ball or the paper's banded "
    "spheroid, 180/360 degree shutter at 30/60 fps (blur up to 3 radii), 720p/1080p, flicker, auto-exposure drift, "
    "rolling shutter, a body leaving the frame; lens distortion, vignetting, sensor noise and H.264/H.265 at a "
    "phone's bit rate throughout. Each clip is calibrated the user's way (chessboard views rendered by the same "
    "camera -> calibrate camera; the apparatus points -> calibrate scene) and tracked with that calibration. RMS "
    "of (u, v), px, and (x, z), mm, over the frames where the body is at least half visible; found: of those "
    "frames. Peers start from the true first box; their (x, z) is their pixel's calibrated ray on the plane "
    "y = 0. render: wall time to ray-trace the clip on this machine (CPU seconds in brackets). ms/frame: uphill's "
    "tracker alone, its set-up and the clip's end included (its thread's CPU time); vs decode: frames per CPU-second of decoding and tracking against "
    "decoding alone (VideoCapture::read, process CPU time; goal >= 80%); both times the best of 3 runs; model: share of the frames found that the "
    "full model (background, colours, smear) measured rather than the fast edge fit. The rolling-shutter clip is "
    "tracked with --readout auto (a phone: its readout measured from the clip; the note gives it).";

std::unique_ptr<TrackMatrixRecord> RunTrackMatrix(const TrackMatrixOptions& o, std::ostream& out) {
  auto record = std::make_unique<TrackMatrixRecord>();
  std::vector<NamedFootage> conditions;
  if (o.conditions.empty()) conditions = RobustnessMatrix();
  else
    for (const std::string& name : o.conditions) conditions.push_back(FootageByName(name));
  const std::string cache = o.cache.empty() ? FootageCacheRoot() : o.cache;
  out << "\nrobustness matrix: " << conditions.size() << " ray-traced clips in " << cache << "\n" << std::flush;

  std::vector<Run> runs;
  std::map<std::string, CameraCalibration> cameras;  // by the boards' folder
  const bool tty = isatty(STDERR_FILENO);
  for (const NamedFootage& named : conditions) {
    Run run;
    run.named = named;
    const FootageCondition& c = named.condition;
    FootageProgress progress;
    progress.report = [&](const std::string& stage, int done, int total) {
      if (tty) std::fprintf(stderr, "\r  rendering %s: %s %d/%d   ", c.name.c_str(), stage.c_str(), done + 1, total);
    };
    run.files = RenderFootage(c, cache, o.fresh, progress);
    if (tty) std::fprintf(stderr, "\r%80s\r", "");
    run.truth = ReadFootageTruth(run.files.truth_csv);
    // The user's path: the camera from the chessboard views, the pose from the apparatus points.
    const std::string boards = fs::path(run.files.boards.front()).parent_path().string();
    if (!cameras.count(boards)) cameras.emplace(boards, CalibrateCameraFromFiles(run.files.boards, c.board_target));
    const CameraCalibration& camera = cameras.at(boards);
    std::vector<ScenePoint> points;
    for (const ApparatusPoint& p : FootageApparatusPoints(c)) points.push_back({p.name, p.pixel, p.position});
    const SceneCalibrationResult scene = CalibrateScene(camera.camera, points, c.camera.camera.width,
                                                        c.camera.camera.height);
    run.calibrated = scene.scene;
    run.calibration_note = Fixed("camera RMS %.3f px", camera.rms_px) + Fixed(", scene RMS %.3f px", scene.rms_px);
    // Tracking.
    std::vector<Position> positions(run.truth.size());
    try {
      // A phone's rolling shutter: the user knows it is one, not its readout (measured).
      TrackVideoOptions options;
      options.tracker.measure_readout = c.shutter.readout > 0;
      const TrackResult track = TrackVideo(run.files.video, c.scene, run.calibrated, options);
      if (track.measured_readout_frames > 0)
        run.calibration_note += Fixed(", readout measured %.1f", 1e3 * track.readout) +
                                (track.readout_u ? Fixed(" ± %.1f", 1e3 * *track.readout_u) : "") + " ms (true " +
                                Fixed("%.1f ms)", 1e3 * c.shutter.readout);
      for (size_t i = 0; i < track.rows.size() && i < positions.size(); ++i) {
        const BallObservation& b = track.rows[i].ball;
        positions[i] = {b.found, b.u, b.v, b.x, b.z, b.full_model};
      }
      run.uphill_says = track.partial ? "partial: " + track.partial_reason : "complete";
      int found = 0, modelled = 0;
      for (const TrackRow& r : track.rows) found += r.ball.found, modelled += r.ball.found && r.ball.full_model;
      run.model_share = found ? static_cast<double>(modelled) / found : 0;
      // The times: the best of kTimingRounds runs of each (a clip takes well under a second, where
      // this machine's CPU time of one run varies by ±30 %), the tracker's from the run above and
      // further ones (the same track: it is deterministic).
      double tracker_seconds = track.tracker_cpu_seconds, decode_seconds = 0;
      long decoded = 0;
      for (int round = 0; round < kTimingRounds; ++round) {
        if (round > 0)
          tracker_seconds = std::min(tracker_seconds,
                                     TrackVideo(run.files.video, c.scene, run.calibrated, options).tracker_cpu_seconds);
        const double cpu0 = ProcessCpuSeconds();
        long frames = 0;
        {
          cv::VideoCapture capture(run.files.video, cv::CAP_FFMPEG);
          cv::Mat frame;
          while (capture.read(frame)) ++frames;
        }
        const double seconds = ProcessCpuSeconds() - cpu0;
        if (round == 0 || seconds < decode_seconds) decode_seconds = seconds;
        decoded = frames;
      }
      run.ms_per_frame = track.rows.empty() ? 0 : 1e3 * tracker_seconds / track.rows.size();
      if (decoded > 0) run.decode_ms_per_frame = 1e3 * decode_seconds / decoded;
    } catch (const InputError& e) {
      run.uphill_says = std::string("error: ") + e.what();
    }
    run.uphill = Compare(run.truth, positions);
    if (!o.positions.empty()) {
      fs::create_directories(o.positions);
      WritePositions((fs::path(o.positions) / (c.name + ".csv")).string(), run.truth, positions);
    }
    runs.push_back(run);
  }

  // The peers, all clips in one run of the script (clips of bad input have no first box).
  std::string why_not = o.why_not_peers;
  TemporaryDirectory positions_dir;
  if (why_not.empty()) {
    std::string command = "OPENCV_FFMPEG_CAPTURE_OPTIONS='threads;1' " + OneCorePython(o.python) + " " +
                          ShellQuote(o.script) + " --positions " + ShellQuote(positions_dir.path().string());
    int clips = 0;
    for (const Run& run : runs) {
      if (run.named.expectation != FootageExpectation::kTrack || run.truth.empty() || !run.truth.front().present)
        continue;
      const SceneCalibration truth_scene = ReadSceneFile(run.files.scene_truth);
      const BallTracker geometry(run.named.condition.scene, truth_scene);
      const ClipTruth& t0 = run.truth.front();
      double r0 = 0;
      for (const Vector2d& p : geometry.Outline(t0.x, t0.z, 32)) r0 += (p - Vector2d(t0.u, t0.v)).norm() / 32;
      command += " " + ShellQuote(run.named.condition.name) + " " + ShellQuote(run.files.video) + " " +
                 ShellQuote(run.files.truth_csv) + Fixed(" %.3f", r0);
      ++clips;
    }
    std::string text;
    out << "running the OpenCV peers on " << clips << " clips ...\n" << std::flush;
    if (clips > 0 && !Capture(command, &text)) why_not = "the peer script failed";
    for (Run& run : runs)
      for (const std::string& peer : kPeers) {
        const std::string path =
            (positions_dir.path() / (run.named.condition.name + "." + peer + ".csv")).string();
        if (fs::exists(path)) run.peers[peer] = Compare(run.truth, ReadPeerPositions(path, run.calibrated));
      }
  }
  if (!why_not.empty()) record->notes.push_back("OpenCV peers skipped: " + why_not);

  record->robustness = Table({{"condition", 16, true},
                              {"render", 11},
                              {"uphill px", 9},
                              {"mm", 7},
                              {"found", 7},
                              {"ms/frame", 8},
                              {"vs decode", 9},
                              {"model", 6},
                              {"CSRT px", 8},
                              {"mm", 7},
                              {"found", 7},
                              {"KCF px", 8},
                              {"mm", 7},
                              {"found", 7},
                              {"Hough px", 8},
                              {"mm", 7},
                              {"found", 7}});
  out << "\n";
  record->robustness.Start(out);
  for (const Run& run : runs) {
    if (run.named.expectation != FootageExpectation::kTrack) continue;
    const double total = run.decode_ms_per_frame + run.ms_per_frame;
    std::vector<std::string> cells = {run.named.condition.name, RenderTime(run.files), Cell(run.uphill, true),
                                      Cell(run.uphill, false), Found(run.uphill), Fixed("%.1f", run.ms_per_frame),
                                      total > 0 ? Fixed("%.0f%%", 100 * run.decode_ms_per_frame / total) : "n/a",
                                      Fixed("%.0f%%", 100 * run.model_share)};
    for (const std::string& peer : kPeers) {
      const auto it = run.peers.find(peer);
      if (it == run.peers.end()) cells.insert(cells.end(), {"n/a", "n/a", "n/a"});
      else cells.insert(cells.end(), {Cell(it->second, true), Cell(it->second, false), Found(it->second)});
    }
    record->robustness.Add(cells);
  }
  record->bad_input = Table({{"bad input", 20, true},
                             {"render", 11},
                             {"uphill says", 60, true},
                             {"reported", 8},
                             {"invented", 8},
                             {"px", 7},
                             {"found", 7}});
  bool any_bad = false;
  for (const Run& run : runs) any_bad = any_bad || run.named.expectation == FootageExpectation::kBadInput;
  if (any_bad) {
    out << "\n";
    record->bad_input.Start(out);
  }
  for (const Run& run : runs) {
    if (run.named.expectation != FootageExpectation::kBadInput) continue;
    record->bad_input.Add({run.named.condition.name, RenderTime(run.files), run.uphill_says,
                           std::to_string(run.uphill.found_any), std::to_string(run.uphill.invented),
                           Cell(run.uphill, true), Found(run.uphill)});
  }
  out << "\nconditions:\n";
  for (const Run& run : runs)
    out << "  " << run.named.condition.name << ": " << run.named.description << " (" << run.calibration_note
        << Fixed(", tracker %.2f ms/frame)", run.ms_per_frame) << "\n";
  for (const std::string& note : record->notes) out << note << "\n";
  return record;
}

}  // namespace uphill::bench
