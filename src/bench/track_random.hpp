// `uphill bench track --random N [--seed S]`: two trackers on N freshly drawn ray-traced scenes
// (bench/track_random_draw.hpp), side by side in one table. How to run it and what each column
// means: docs/bench.md, "Random scenes".
//
// Each draw is rendered once into <cache>/<S>/ (footage/footage_clip.hpp; a rerun with the same
// seed reads it), decoded once, and given to both trackers in the same process with the true
// camera and scene. Scored against the truth: the renderer's projected centre per frame, and
// x(t) of uphill::Motion (src/motion) at the time each tracker states for its position.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/camera.hpp"

namespace uphill::bench {

// A tracker's position in one frame.
struct TrackedFrame {
  bool found = false;
  double u = 0, v = 0;          // raw pixel of the centre
  double uncertainty_px = NAN;  // its standard uncertainty, if the tracker states one
  double x = 0;                 // centre along the rails, m
  double t = 0;                 // s: the time the tracker states for this position
};

struct TrackerOutput {
  std::vector<TrackedFrame> frames;  // one per decoded frame (fewer if it stopped)
  std::string models = "-";          // the models it chose (its track sidecar's "models"), or "-"
  std::string refusal;               // set when it refused the clip (no frames): why
};

// What both trackers get: the file, its frames decoded once, the true camera and scene.
struct DecodedClip {
  std::string video;
  std::vector<cv::Mat> frames;  // 8-bit BGR
  Scene scene;
  SceneCalibration calibration;
  double fps = 30;
  bool rolling_shutter = false;  // the user knows a phone's sensor reads rows in turn, not the readout
  std::string work_dir;          // for the tracker's files (its sidecar)
};

// A tracker under comparison: the clip in, a position per frame out. Throws only for a failure
// of the benchmark itself; the clip's refusal goes into TrackerOutput::refusal.
using ClipTracker = std::function<TrackerOutput(const DecodedClip&)>;

// "core": `uphill track`'s path (TrackVideo on the file, the sidecar written and read back), with
// TrackerOptions::min_report_quality as given.
TrackerOutput TrackWithCore(const DecodedClip& clip, double min_report_quality = TrackerOptions{}.min_report_quality);
// "baseline": the edge-fit tracker of bench/baseline_edge_tracker.hpp fed the decoded frames.
TrackerOutput TrackWithBaseline(const DecodedClip& clip);

struct TrackRandomOptions {
  int draws = 0;
  std::optional<std::uint64_t> seed;  // unset: drawn from std::random_device
  std::string cache = "/tmp/uphill-bench-random";
  bool fresh = false;                 // render again
  std::string json;                   // "" = no JSON file
  std::vector<std::string> only;      // non-empty: only the draws with these ids (to replay one)
  ClipTracker core = [](const DecodedClip& clip) { return TrackWithCore(clip); };
  ClipTracker baseline = TrackWithBaseline;
};

// Renders (or reuses) the draws, tracks each with both trackers, prints a row per draw and the
// percentiles over the draws, and writes the JSON file if asked. Throws std::runtime_error when
// povray or ffmpeg is missing.
void RunTrackRandom(const TrackRandomOptions& options, std::ostream& out);

}  // namespace uphill::bench
