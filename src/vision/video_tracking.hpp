// Video tracking: runs the BallTracker over every frame of a video file and writes the track CSV
// and its sidecar JSON (formats in data/README.md, "Track CSV"). What `uphill track` does, as a
// library so that the tests and `uphill bench track` run exactly the same code.
//
// Time: the container's timestamp of each frame (CAP_PROP_POS_MSEC), which keeps dropped or
// variable-rate frames honest. OpenCV reports 0 for the last frames that FFmpeg drains from its
// decoder at the end of some files; a timestamp that does not increase is replaced by the
// previous one + 1/fps (and counted in TrackResult::extrapolated_times).
//
// Bad input (InputError naming the file): a file that is not a video OpenCV can read; a video
// whose frame size differs from the calibration's; a video in which the ball is found in no
// frame. Partial results: a video that ends before the frame count its container declares
// (truncated or corrupt), or a ball that is lost and never found again, give partial = true
// with the reason; the rows read are kept.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "vision/ball_tracker.hpp"

namespace uphill {

struct TrackRow {
  int frame = 0;
  double t = 0;  // s
  BallObservation ball;
};

struct TrackResult {
  std::vector<TrackRow> rows;
  double fps = 0;               // the container's nominal rate
  long declared_frames = 0;     // the container's frame count (0: unknown)
  int extrapolated_times = 0;   // timestamps replaced (see above)
  double tracker_cpu_seconds = 0;  // CPU time of the tracker itself (this thread, decoding excluded)
  bool partial = false;
  std::string partial_reason;
};

struct TrackVideoOptions {
  TrackerOptions tracker;
  std::string calibration_name = "the scene file";  // for messages
  // Optional: the video with the fit drawn (.mp4). Written under a temporary name beside it and
  // renamed into place when the track is complete: never half-written, its folder created.
  std::string overlay_path;
  // Called after each frame with (frames done, declared total or 0).
  std::function<void(int, long)> progress;
};

// Opens with the FFmpeg backend (its own log lines silenced: library_logs.hpp). Throws
// InputError for a video that cannot be read or holds no ball, EnvironmentError when the overlay
// cannot be written. The caller sets one-core decoding if it wants it
// (OPENCV_FFMPEG_CAPTURE_OPTIONS="threads;1" before the call, cv::setNumThreads(1)).
TrackResult TrackVideo(const std::string& video_path, const Scene& scene, const SceneCalibration& calibration,
                       const TrackVideoOptions& options = {});

// Files named in the sidecar (`<csv>.json`, format "uphill-track/1").
struct TrackSources {
  std::string video, camera, scene, body;
};

// Writes the CSV (header `frame,t,u,v,radius_px,x,z,quality`; x z in mm) and the sidecar, each
// atomically, creating the CSV's folder if needed. Throws EnvironmentError when a file cannot be
// written.
void WriteTrack(const std::string& csv_path, const TrackResult& result, const TrackSources& sources);

}  // namespace uphill
