// `uphill bench track`: speed and accuracy of the ball tracker (src/vision) on synthetic clips
// with exact ground truth (src/vision/synthetic_clip.hpp), against the limit set by decoding, and
// against OpenCV's CSRT and KCF trackers and HoughCircles when /usr/bin/python3 has cv2
// (tools/bench/track_peers.py, run on the same files).
//
// Clips (rendered once, then reused from /tmp/uphill-bench-track/): the default apparatus
// (DefaultClipSetup: a 2-inch ball on 8 mm rods, 1 m apparatus, side view, k1 = −0.1), 120 frames
// at 30 fps: at rest for 1.8 s, then released just below X it rolls back toward O, up to ~16 px per
// frame at 720p, and leaves the rails at O in the last frames:
//   720p-clean     1280×720, sharp, no noise, lossless FFV1 (.avi)
//   720p-h264      1280×720, motion blur (1/60 s exposure, 6 sub-frames), noise σ = 2, flicker 1 %, H.264
//   1080p-h264     1920×1080, the same degradations
// Speed: frames per CPU-second of the whole process (one core's work; best of 3; OpenCV's own
// parallel loops off): decoding alone (VideoCapture::read of every frame), and tracking with the
// decoding included (TrackVideo). Accuracy: RMS of (u, v) against the truth, px, and of (x, z),
// mm, over the frames where the ball is in the picture with at least half its outline visible.
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

#include "bench_support.hpp"
#include "commands.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/synthetic_clip.hpp"
#include "vision/video_tracking.hpp"

namespace uphill::cli {
namespace {

namespace fs = std::filesystem;
using namespace uphill::vision;

// Bump when the renderer or the clip settings change, so that cached clips are not reused.
constexpr const char* kClipVersion = "v3";
constexpr int kFrames = 120;
constexpr double kReleaseTime = 1.8;  // s: at rest until then, as a lab clip starts

struct Flags {
  std::string cache = "/tmp/uphill-bench-track";
  std::string python = "/usr/bin/python3";
  std::string script;
  bool no_python = false, fresh = false;
};

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
  std::printf("rendering %s (%dx%d) ...\n", clip.name.c_str(), clip.width, clip.height);
  std::fflush(stdout);
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
};

void Run(const Flags& f) {
  // One core's work: OpenCV's parallel loops off; FFmpeg's decoder threads are counted by the
  // process clock (OPENCV_FFMPEG_CAPTURE_OPTIONS reaches only the demuxer in OpenCV 4.6).
  setenv("OPENCV_FFMPEG_CAPTURE_OPTIONS", "threads;1", 1);
  cv::setNumThreads(1);
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
  std::printf("\nuphill bench track: the default synthetic apparatus (2-inch ball on 8 mm rods, 1 m, side view,\n"
              "k1 = -0.1), 120 frames at 30 fps, at rest for 1.8 s then rolling; clips in %s.\n"
              "fps: frames per CPU-second of the process (one core's work; best of 3); decode = VideoCapture::read\n"
              "only, track = uphill's tracker with the decoding included; ms/frame = the tracker alone (its\n"
              "thread's CPU time). RMS over frames with the ball at least half visible.\n\n",
              cache.string().c_str());
  std::printf("%-12s %9s %9s %7s %9s %10s %10s %8s\n", "clip", "decode", "track", "ratio", "ms/frame", "RMS (u,v)",
              "RMS (x,z)", "found");
  std::map<std::string, double> uphill_rms, decode_fps;
  for (const Clip& c : clips) {
    const ClipSetup& setup = setups.at(std::to_string(c.width));
    const double decode = bench::BestOf(3, [&] {
      cv::VideoCapture cap(c.video, cv::CAP_FFMPEG);
      cv::Mat frame;
      while (cap.read(frame)) {
      }
    }, bench::ProcessCpuSeconds);
    TrackResult track;
    // Process CPU time: FFmpeg decodes in its own threads (OpenCV 4.6 sets the decoder's thread
    // count itself), so one thread's clock would miss most of the decoding.
    const double tracking = bench::BestOf(
        3, [&] { track = TrackVideo(c.video, setup.scene, setup.calibration); }, bench::ProcessCpuSeconds);
    const Accuracy a = Score(c, track);
    const double n = static_cast<double>(track.rows.size());
    decode_fps[c.name] = n / decode;
    uphill_rms[c.name] = a.rms_px;
    std::printf("%-12s %9.1f %9.1f %6.0f%% %9.3f %7.3f px %7.3f mm %4d/%-3d\n", c.name.c_str(), n / decode,
                n / tracking, 100 * decode / tracking, 1e3 * track.tracker_cpu_seconds / n, a.rms_px, a.rms_mm,
                a.compared, Comparable(c));
  }

  // Peers.
  std::string why_not;
  const std::string script = f.script.empty() ? bench::FindUpward("tools/bench/track_peers.py") : f.script;
  if (f.no_python) why_not = "--no-python";
  else if (access(f.python.c_str(), X_OK) != 0) why_not = f.python + " not found";
  else if (script.empty()) why_not = "tools/bench/track_peers.py not found (use --script)";
  else if (std::system((bench::ShellQuote(f.python) + " -c 'import cv2' > /dev/null 2>&1").c_str()) != 0)
    why_not = f.python + " has no OpenCV (apt-get install python3-opencv)";
  std::vector<PeerRow> peers;
  if (why_not.empty()) {
    std::string command = "OPENCV_FFMPEG_CAPTURE_OPTIONS='threads;1' " + bench::OneCorePython(f.python) + " " +
                          bench::ShellQuote(script);
    for (const Clip& c : clips) {
      // The peers get the truth's first box (centre and outline radius): an advantage over uphill.
      const ClipSetup& setup = setups.at(std::to_string(c.width));
      const BallTracker geometry(setup.scene, setup.calibration);
      double r0 = 0;
      const ClipTruth& t0 = c.truth.front();
      for (const Eigen::Vector2d& p : geometry.Outline(t0.x, t0.z, 32)) r0 += (p - Eigen::Vector2d(t0.u, t0.v)).norm() / 32;
      char extra[96];
      std::snprintf(extra, sizeof extra, " %.3f", r0);
      command += " " + bench::ShellQuote(c.name) + " " + bench::ShellQuote(c.video) + " " + bench::ShellQuote(c.truth_csv) + extra;
    }
    std::string out;
    std::printf("\nrunning the OpenCV peers (%s) ...\n", script.c_str());
    std::fflush(stdout);
    if (!bench::Capture(command, &out)) why_not = "the peer script failed";
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {  // method clip fps rms_px frames
      PeerRow row;
      if (std::istringstream(line) >> row.method >> row.clip >> row.fps >> row.rms_px >> row.compared) peers.push_back(row);
    }
  }
  if (!peers.empty()) {
    std::printf("\n%-20s %-12s %9s %10s %8s %14s %14s\n", "peer (Python cv2)", "clip", "fps", "RMS (u,v)", "frames",
                "fps / decode", "RMS / uphill");
    for (const PeerRow& p : peers)
      std::printf("%-20s %-12s %9.1f %7.3f px %8d %13.0f%% %13.1fx\n", p.method.c_str(), p.clip.c_str(), p.fps, p.rms_px,
                  p.compared, 100 * p.fps / decode_fps[p.clip], p.rms_px / std::max(uphill_rms[p.clip], 1e-9));
  }
  if (!why_not.empty()) std::printf("\nOpenCV peers skipped: %s\n", why_not.c_str());
  std::printf("\nGoal: tracking >= 80%% of decode-only fps on one core at <= 0.1 px RMS (u, v).\n");
}

}  // namespace

void AddBenchTrack(CLI::App& bench) {
  auto flags = std::make_shared<Flags>();
  CLI::App* cmd = bench.add_subcommand("track", "Ball tracking: fps against decoding, RMS error, OpenCV peers");
  cmd->add_option("--cache", flags->cache, "folder of the rendered clips (reused between runs)")->capture_default_str();
  cmd->add_flag("--fresh", flags->fresh, "render the clips again");
  cmd->add_option("--python", flags->python, "Python with cv2 for the peers")->capture_default_str();
  cmd->add_option("--script", flags->script, "path of tools/bench/track_peers.py");
  cmd->add_flag("--no-python", flags->no_python, "skip the OpenCV peers");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
