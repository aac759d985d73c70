// Tracking a video file: the ball's centre in every frame (vision/video_tracking.hpp), filmed with
// a camera file (`uphill calibrate camera`) and a scene file (`uphill calibrate scene`) that
// belong together. The use case of `uphill track` (docs/track.md), of each video trial of an
// experiment (app/video_trials.hpp: `uphill fit`/`report` and the page) and of Python's
// uphill.track: the checks, the calibration and the tracker's settings are decided here once.
//
// Order of the checks, each an InputError before any frame is decoded:
//   1. the body: a double cone is refused (kDoubleConeRefusal; the tracker fits the outline of a
//      sphere or a spheroid);
//   2. the calibration (app/tracking_inputs.hpp): the scene file must have been calibrated with
//      the camera file's camera;
//   3. the file (app/video_frames.hpp, ProbeVideo): a video FFmpeg decodes, not a still picture
//      (at least two frames), whose frame size is within the decode limit.
// Then TrackVideo throws InputError for a video that holds no ball, and
// EnvironmentError when the overlay cannot be written.
//
// Units: SI (m, s); pixels are raw pixels of the video's frames.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>

#include "model/scene.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/video_tracking.hpp"

namespace uphill {

// The camera's settings and the outputs of a tracking run. The defaults are every front end's.
struct TrackVideoFileOptions {
  std::optional<Eigen::Vector2d> init_uv;          // raw pixel near the centre in the first frame
  std::optional<double> exposure;                  // s per frame; unset: measured from the motion blur
  double readout = 0;                              // s, first to last row; 0: a global shutter
  bool measure_readout = false;                    // a rolling shutter of unknown readout ("auto")
  VideoTransfer transfer = VideoTransfer::kSrgb;   // the video's transfer curve
  double min_report_quality = TrackerOptions{}.min_report_quality;  // TrackerOptions' rule
  std::string overlay_path;                        // "" : none; else the video with the fit drawn (.mp4)
  std::string video_label;                         // names the video in messages ("": its path)
  std::string scene_label;                         // names the scene file in messages ("": its path)
};

// "srgb" (cameras) or "linear". Throws InputError(quantity, "must be srgb or linear (got '…')").
VideoTransfer ParseVideoTransfer(const std::string& name, const std::string& quantity = "transfer");

// Called after each frame with (frames done, the container's declared total or 0).
using FrameProgressCallback = std::function<void(int done, long total)>;

// The track of `video` (any file FFmpeg decodes) of `scene` (its body and rails, SI), filmed with
// `camera_file` and `scene_file`. Decoding uses the threads FFmpeg chooses unless the caller set
// one thread per video (app/video_trials.hpp, OneDecodeThreadPerVideo).
TrackResult TrackVideoFile(const std::string& video, const std::string& camera_file, const std::string& scene_file,
                           const Scene& scene, const TrackVideoFileOptions& options = {},
                           const FrameProgressCallback& progress = {});

}  // namespace uphill
