// Video tracking: runs the BallTracker over every frame of a video file and writes the track CSV
// and its sidecar JSON (formats in data/README.md, "Track CSV"). What `uphill track` does, as a
// library so that the tests and `uphill bench track` run exactly the same code.
//
// Time: the container's timestamp of each frame (CAP_PROP_POS_MSEC), which keeps dropped or
// variable-rate frames honest. OpenCV reports 0 for the last frames that FFmpeg drains from its
// decoder at the end of some files; a timestamp that does not increase is replaced by the
// previous frame's timestamp + 1/fps (the frame's, not its row time under a rolling shutter;
// counted in TrackResult::extrapolated_times).
//
// Time: see ball_tracker.hpp: each row's t is the frame's timestamp plus the rolling shutter's
// delay of the row where the centre lies (0 for a global shutter): the centre's mid-exposure.
//
// Bad input (InputError naming the file): a file that is not a video OpenCV can read; a video
// whose frame size differs from the calibration's. Partial results (partial = true with the
// reason; every row read is kept, never a position invented):
//  - input_problem = true (the input's fault, `uphill track` exits 2): a video that ends before
//    the frame count its container declares (truncated or corrupt); a picture that changed
//    outside the body (the camera moved: no positions from that frame on); a video in which the
//    body is found in no frame; an exposure that changed during the clip (positions kept);
//  - input_problem = false: a ball that is lost and never found again (it dropped out of view:
//    how runs end).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vision/ball_tracker.hpp"

namespace uphill {

struct TrackRow {
  int frame = 0;
  double t = 0;  // s
  BallObservation ball;
  // Where the ball was found: the standard uncertainty of its centre, in raw pixels (each image
  // axis) and along the path (m, at the body's scale: Body::across over radius_px). The tracker's
  // systematic error as analyse-track takes it (TrackAnalysisOptions: tracker_floor_px +
  // tracker_blur × the pixels the centre moves per frame interval, from the found frames before
  // and after), or this frame's own outline spread where larger (BallObservation::
  // outline_spread_px, which analyse-track also reads at rest), and, in quadrature, a single
  // position's scatter beyond it, 0.10 px (calibrated on random ray-traced scenes:
  // video_tracking.cpp). `uphill bench track --random` states how often the truth lies within
  // 2.45 u_px (95 % expected).
  double u_px = 0, u_x = 0;
};

struct TrackResult {
  std::vector<TrackRow> rows;
  double fps = 0;               // the container's nominal rate
  long declared_frames = 0;     // the container's frame count (0: unknown)
  int extrapolated_times = 0;   // timestamps replaced (see above)
  // CPU time of the tracker itself: its set-up, the frames and the clip's end (refits, the
  // readout's settling); this thread's, decoding excluded.
  double tracker_cpu_seconds = 0;
  bool partial = false;
  bool input_problem = false;   // partial because of the input (exit status 2), not a ball lost at the end
  std::string partial_reason;
  // The camera's settings as used: the exposure given (TrackerOptions::exposure) or measured from
  // the smear, the rolling shutter's readout, the transfer curve.
  std::optional<double> exposure, measured_exposure;
  int measured_exposure_frames = 0;
  // As used: given, or measured (measured_readout_frames > 0), or, asked for and not measurable,
  // half a frame (readout_u then 1/(fps·√12), the spread of the range 0 … 1/fps).
  double readout = 0;
  int measured_readout_frames = 0;
  bool readout_asked = false;       // --readout auto: to be measured (it may not have been)
  std::optional<double> readout_u;  // s, the measured (or assumed) readout's standard uncertainty
  int image_height = 0;             // px, the rows the readout spans
  VideoTransfer transfer = VideoTransfer::kSrgb;
  std::vector<long> exposure_changes;  // frames where the exposure jumped
  long frames_left_off_path = 0;       // BallTracker::FramesLeftOffPath
  // Positions of a quality below TrackerOptions::min_report_quality that lay off the motion of the
  // frames around them: left out (internal/doubtful_rows.hpp).
  long frames_of_poor_fit = 0;
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

// Writes the CSV (header `frame,t,u,v,radius_px,x,z,quality,u_px,u_x,u_outline_px`; x z u_x in mm) and the sidecar, each
// atomically, creating the CSV's folder if needed. Throws EnvironmentError when a file cannot be
// written.
void WriteTrack(const std::string& csv_path, const TrackResult& result, const TrackSources& sources);

}  // namespace uphill
