#include "bench/track_benchmark.hpp"

#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "bench/track_matrix.hpp"
#include "bench/track_random.hpp"
#include "vision/ball_tracker.hpp"
#include "footage/synthetic_clip.hpp"
#include "vision/video_tracking.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;

// Bump when the renderer or the clip settings change, so that cached clips are not reused.
constexpr const char* kClipVersion = "v4";
constexpr int kFrames = 120;
constexpr double kReleaseTime = 1.8;  // s: at rest until then, as a lab clip starts


struct Clip {
  std::string name;
  int width, height;
  bool degraded;
  std::string video, truth_csv;
  std::vector<ClipTruth> truth;
};

std::vector<ClipTruth> ReadTruth(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<ClipTruth> out;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    while (cells.size() < 7) cells.emplace_back();
    ClipTruth t;
    t.frame = std::stoi(cells[0]);
    t.t = std::stod(cells[1]);
    t.present = !cells[2].empty();
    if (t.present) {
      t.x = std::stod(cells[2]) * 1e-3, t.z = std::stod(cells[3]) * 1e-3;
      t.u = std::stod(cells[4]), t.v = std::stod(cells[5]), t.visibility = std::stod(cells[6]);
    }
    out.push_back(t);
  }
  return out;
}

void Prepare(Clip& clip, const ClipSetup& setup, bool fresh) {
  if (!fresh && fs::exists(clip.video) && fs::exists(clip.truth_csv)) {
    clip.truth = ReadTruth(clip.truth_csv);
    if (clip.truth.size() == kFrames) return;
  }
  std::fprintf(stderr, "rendering %s (%dx%d) ...\n", clip.name.c_str(), clip.width, clip.height);
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const Motion motion(setup.scene, setup.x0);
  ClipSettings s;
  s.frames = kFrames;
  s.release_time = kReleaseTime;
  if (clip.degraded) {
    s.blur_samples = 6;
    s.exposure = 1.0 / 60;
    s.noise_sigma = 2;
    s.flicker = 0.01;
  }
  clip.truth = RenderClip(renderer, motion, s, clip.video);
  WriteClipTruthCsv(clip.truth_csv, clip.truth);
}

struct Accuracy {
  double rms_px = 0, rms_mm = 0;
  int compared = 0, found = 0;
};

Accuracy Score(const Clip& clip, const TrackResult& track) {
  Accuracy a;
  double s_px = 0, s_mm = 0;
  for (size_t i = 0; i < clip.truth.size() && i < track.rows.size(); ++i) {
    const ClipTruth& t = clip.truth[i];
    const BallObservation& b = track.rows[i].ball;
    a.found += b.found;
    if (!t.present || t.visibility < 0.5 || !b.found) continue;
    s_px += std::pow(b.u - t.u, 2) + std::pow(b.v - t.v, 2);
    s_mm += (std::pow(b.x - t.x, 2) + std::pow(b.z - t.z, 2)) * 1e6;
    ++a.compared;
  }
  if (a.compared) a.rms_px = std::sqrt(s_px / a.compared), a.rms_mm = std::sqrt(s_mm / a.compared);
  return a;
}

int Comparable(const Clip& clip) {
  int n = 0;
  for (const ClipTruth& t : clip.truth) n += t.present && t.visibility >= 0.5;
  return n;
}

struct PeerRow {
  std::string method, clip;
  double fps, rms_px;
  int compared;
  std::uint64_t peak_bytes = 0;
};

// Clips (rendered once, then reused from the cache folder): the default apparatus
// (DefaultClipSetup: a 2-inch ball on 8 mm rods, 1 m apparatus, side view, k1 = −0.1), 120 frames
// at 30 fps: at rest for 1.8 s, then released just below X it rolls back toward O, up to ~16 px per
// frame at 720p, and leaves the rails at O in the last frames:
//   720p-clean     1280×720, sharp, no noise, lossless FFV1 (.avi)
//   720p-h264      1280×720, motion blur (1/60 s exposure, 6 sub-frames), noise σ = 2, flicker 1 %, H.264
//   1080p-h264     1920×1080, the same degradations
constexpr const char* kMethod =
    "Synthetic clips with exact ground truth (src/footage/synthetic_clip.hpp): the default apparatus (a 2-inch "
    "ball on 8 mm rods, 1 m, side view, k1 = -0.1), 120 frames at 30 fps, at rest for 1.8 s, then rolling; "
    "720p-clean (sharp, lossless FFV1), 720p-h264 and 1080p-h264 (motion blur over 1/60 s, noise sigma 2, "
    "flicker 1 %, H.264). Speed: frames per CPU-second of the whole process (one core's work; best of 3; "
    "OpenCV's parallel loops off): decoding alone (VideoCapture::read) and tracking with decoding included "
    "(TrackVideo); ms/frame: the tracker alone, its set-up and the clip's end included. Accuracy: RMS of (u, v) against the truth, px, and of (x, z), "
    "mm, over the frames where at least half the ball is visible. Peers (tools/bench/track_peers.py): OpenCV's "
    "CSRT and KCF trackers and HoughCircles on the same files, started from the true first box. \"peak RSS\": "
    "the process's peak resident memory over the row.";

// The robustness table (bench/track_matrix.hpp) added to the section, then the record.
void RunMatrix(const TrackBenchmarkOptions& f, Section& section, std::unique_ptr<TrackMatrixRecord>& matrix,
               std::ostream& out) {
  TrackMatrixOptions m;
  m.cache = f.footage_cache;
  m.conditions = f.conditions;
  m.fresh = f.fresh;
  m.positions = f.positions;
  m.python = f.common.python;
  m.script = f.script.empty() ? FindUpward("tools/bench/track_peers.py") : f.script;
  m.why_not_peers = PeerUnavailable(f.no_python ? "--no-python" : "", f.common.python, m.script,
                                    "tools/bench/track_peers.py not found (use --script)", "cv2");
  matrix = RunTrackMatrix(m, out);
  section.method += std::string("\n\n") + kTrackMatrixMethod;
  section.tables.emplace_back("Robustness on ray-traced footage (one condition per row):", &matrix->robustness);
  if (!matrix->bad_input.empty()) section.tables.emplace_back("Bad input:", &matrix->bad_input);
  section.notes.insert(section.notes.end(), matrix->notes.begin(), matrix->notes.end());
  const std::string goal = "Goal (issue 10): every condition RMS (u, v) <= 0.3 px and (x, z) <= 0.5 mm with all "
                           "frames found; clean <= 0.1 px.";
  out << "\n" << goal << "\n";
  section.results.push_back(goal);
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace

void RunTrackBenchmark(const TrackBenchmarkOptions& f, std::ostream& out) {
  // A run of some of the robustness conditions keeps its own section, so that the last run of the
  // whole matrix (hours of rendering) stays beside it.
  std::string name = "track";
  if (f.only_matrix && !f.conditions.empty()) {
    name += " --only-matrix --conditions ";
    for (size_t i = 0; i < f.conditions.size(); ++i) name += (i ? "," : "") + f.conditions[i];
  }
  Section section = StartSection(name, f.common.command, kMethod);
  section.versions.emplace_back("OpenCV (C++)", CV_VERSION);
  // One core's work: OpenCV's parallel loops off; FFmpeg's decoder threads are counted by the
  // process clock (OPENCV_FFMPEG_CAPTURE_OPTIONS reaches only the demuxer in OpenCV 4.6).
  setenv("OPENCV_FFMPEG_CAPTURE_OPTIONS", "threads;1", 1);
  cv::setNumThreads(1);
  if (f.random > 0) {
    TrackRandomOptions random;
    random.draws = f.random;
    random.seed = f.seed;
    random.cache = f.random_cache;
    random.fresh = f.fresh;
    random.json = f.json;
    random.only = f.draw_ids;
    if (f.min_quality) random.core = [q = *f.min_quality](const DecodedClip& clip) { return TrackWithCore(clip, q); };
    return RunTrackRandom(random, out);
  }
  std::unique_ptr<TrackMatrixRecord> matrix;
  if (f.only_matrix) return RunMatrix(f, section, matrix, out);
  const fs::path cache = fs::path(f.cache) / kClipVersion;
  fs::create_directories(cache);
  std::vector<Clip> clips = {{"720p-clean", 1280, 720, false, "", "", {}},
                             {"720p-h264", 1280, 720, true, "", "", {}},
                             {"1080p-h264", 1920, 1080, true, "", "", {}}};
  std::map<std::string, ClipSetup> setups;
  for (Clip& c : clips) {
    c.video = (cache / (c.name + (c.degraded ? ".mp4" : ".avi"))).string();
    c.truth_csv = (cache / (c.name + ".truth.csv")).string();
    const std::string key = std::to_string(c.width);
    if (!setups.count(key)) setups.emplace(key, DefaultClipSetup(c.width, c.height));
    Prepare(c, setups.at(key), f.fresh);
  }
  out << "\nuphill bench track: the default synthetic apparatus (2-inch ball on 8 mm rods, 1 m, side view,\n"
         "k1 = -0.1), 120 frames at 30 fps, at rest for 1.8 s then rolling; clips in "
      << cache.string()
      << ".\nfps: frames per CPU-second of the process (one core's work; best of 3); decode = VideoCapture::read\n"
         "only, track = uphill's tracker with the decoding included; ms/frame = the tracker alone, its\n"
         "set-up and the clip's end included (its thread's CPU time). RMS over frames with the ball at least half visible.\n\n";
  Table table({{"clip", 12, true}, {"decode fps", 10}, {"track fps", 9}, {"ratio", 6}, {"ms/frame", 8},
               {"RMS (u,v)", 9}, {"RMS (x,z)", 9}, {"found", 7}, {"peak RSS", 8}});
  table.Start(out);
  std::map<std::string, double> uphill_rms, decode_fps;
  const auto fixed = [](const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return std::string(buf);
  };
  for (const Clip& c : clips) {
    const ClipSetup& setup = setups.at(std::to_string(c.width));
    const double decode = BestOf(3, [&] {
      cv::VideoCapture cap(c.video, cv::CAP_FFMPEG);
      cv::Mat frame;
      while (cap.read(frame)) {
      }
    }, ProcessCpuSeconds);
    TrackResult track;
    // Process CPU time: FFmpeg decodes in its own threads (OpenCV 4.6 sets the decoder's thread
    // count itself), so one thread's clock would miss most of the decoding.
    const Measurement tracking =
        Measure(3, [&] { track = TrackVideo(c.video, setup.scene, setup.calibration); }, ProcessCpuSeconds);
    const Accuracy a = Score(c, track);
    const double n = static_cast<double>(track.rows.size());
    decode_fps[c.name] = n / decode;
    uphill_rms[c.name] = a.rms_px;
    table.Add({c.name, fixed("%.1f", n / decode), fixed("%.1f", n / tracking.seconds),
               fixed("%.0f%%", 100 * decode / tracking.seconds), fixed("%.3f", 1e3 * track.tracker_cpu_seconds / n),
               fixed("%.3f px", a.rms_px), fixed("%.3f mm", a.rms_mm),
               std::to_string(a.compared) + "/" + std::to_string(Comparable(c)), FormatBytes(tracking.peak_bytes)});
  }
  section.tables.emplace_back("", &table);

  // Peers.
  const std::string script = f.script.empty() ? FindUpward("tools/bench/track_peers.py") : f.script;
  std::string why_not = PeerUnavailable(f.no_python ? "--no-python" : "", f.common.python, script,
                                        "tools/bench/track_peers.py not found (use --script)", "cv2");
  std::vector<PeerRow> peers;
  if (why_not.empty()) {
    std::string command =
        "OPENCV_FFMPEG_CAPTURE_OPTIONS='threads;1' " + OneCorePython(f.common.python) + " " + ShellQuote(script);
    for (const Clip& c : clips) {
      // The peers get the truth's first box (centre and outline radius): an advantage over uphill.
      const ClipSetup& setup = setups.at(std::to_string(c.width));
      const BallTracker geometry(setup.scene, setup.calibration);
      double r0 = 0;
      const ClipTruth& t0 = c.truth.front();
      for (const Eigen::Vector2d& p : geometry.Outline(t0.x, t0.z, 32)) r0 += (p - Eigen::Vector2d(t0.u, t0.v)).norm() / 32;
      command += " " + ShellQuote(c.name) + " " + ShellQuote(c.video) + " " + ShellQuote(c.truth_csv) + fixed(" %.3f", r0);
    }
    std::string text;
    out << "\nrunning the OpenCV peers (" << script << ") ...\n" << std::flush;
    if (!Capture(command, &text)) why_not = "the peer script failed";
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {  // "versions Python X OpenCV Y", or method clip fps rms_px frames peak_bytes
      std::istringstream fields(line);
      PeerRow row;
      if (line.rfind("versions ", 0) == 0) {
        std::string word, name, version;
        fields >> word;
        while (fields >> name >> version) section.versions.emplace_back(name, version);
      } else if (fields >> row.method >> row.clip >> row.fps >> row.rms_px >> row.compared >> row.peak_bytes) {
        peers.push_back(row);
      }
    }
  }
  Table peer_table({{"peer (Python cv2)", 18, true}, {"clip", 12, true}, {"fps", 8}, {"RMS (u,v)", 10}, {"frames", 6},
                    {"fps / decode", 12}, {"RMS / uphill", 12}, {"peak RSS", 8}});
  if (!peers.empty()) {
    out << "\n";
    peer_table.Start(out);
    for (const PeerRow& p : peers)
      peer_table.Add({p.method, p.clip, fixed("%.1f", p.fps), fixed("%.3f px", p.rms_px), std::to_string(p.compared),
                      fixed("%.0f%%", 100 * p.fps / decode_fps[p.clip]),
                      fixed("%.1fx", p.rms_px / std::max(uphill_rms[p.clip], 1e-9)), FormatBytes(p.peak_bytes)});
    section.tables.emplace_back("OpenCV's trackers on the same clips:", &peer_table);
  }
  if (!why_not.empty()) {
    out << "\nOpenCV peers skipped: " << why_not << "\n";
    section.notes.push_back("OpenCV peers skipped: " + why_not);
  }
  const std::string goal = "Goal: tracking >= 80% of decode-only fps on one core at <= 0.1 px RMS (u, v).";
  out << "\n" << goal << "\n";
  section.results.push_back(goal);
  if (!f.no_matrix) return RunMatrix(f, section, matrix, out);
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace uphill::bench
