// Physically based test footage of the apparatus: clips ray-traced by POV-Ray, independent of the
// tracker (which was developed against synthetic_clip.hpp), with exact ground truth. The issue's
// robustness matrix (footage_conditions.hpp) and the tests of the tracker run on it.
//
// A clip (RenderFootage) is made as a camera makes it:
//  1. the scene (povray_scene.hpp) is ray-traced by POV-Ray (povray_render.hpp) as a pinhole
//     picture wider than the frame, in linear light: once without the body (the static scene),
//     then per frame only a window around the body, its soft shadow and its reflections, once per
//     sub-frame time (below), each window composited into the static picture;
//  2. the lens: every raw pixel takes the pinhole picture's value along its viewing ray
//     (lens_remap.hpp), so the raw frame is seen through OpenCV's distortion model exactly, and
//     relative illumination (vignetting, (1 − s) + s·cos⁴θ) multiplies it;
//  3. the exposure (sensor_model.hpp): each raw row integrates the scene over its own exposure
//     window (global or rolling shutter, ShutterTiming), weighted by the light's flicker and the
//     auto-exposure drift: the sub-frames are rendered at K times spaced so that no point of the
//     body moves more than `max_step_px` between them (the motion blur of a fast body is the
//     average of many sub-frames, in linear light), and a row's value is Σ_k w_k·picture_k with
//     w_k = ∫ g(t) dt over the overlap of sub-frame k's time slot with the row's window, / E;
//  4. the sensor: gain, shot and read noise (Philox, seeded), clipping, sRGB, 8 bits;
//  5. compression: H.264, H.265 or lossless FFV1 through ffmpeg (video_encoder.hpp).
//
// Motion: uphill::Motion of the scene from x0 at `release_time` (at rest before it; released from
// rest, or pushed with FootageCondition::motion's v0, with its rolling resistance μ), centre
// (x, 0, z(x)) and rolling angle about +y (povray_scene.hpp turns the body by it).
// Once the motion has ended (fall-off, or the contact reaches O) the body is gone; a frame whose
// exposure contains the end shows no body.
//
// Ground truth (truth.csv, format of synthetic_clip.hpp's WriteClipTruthCsv:
// frame,t,x,z,u,v,visibility): per frame the time t* at which the body's centre is reported,
// its (x, z) from Motion at t*, and (u, v) = ProjectApparatusPoint(camera, pose of that frame,
// (x, 0, z)) (cv::projectPoints). t* is the mid-exposure of the row where the centre lies:
// t* = t_f + v(t*)·readout/H, solved by fixed-point iteration to 1e-12 s (it contracts by
// |dv/dt|·readout/H < 0.1); for a global shutter t* = t_f = f/fps, the frame's timestamp.
// visibility: the fraction of the body's silhouette (its projected area, sampled by 32 × 32 rays)
// that lies inside the frame and is not hidden by a rail, the crossbar or a post. A frame without
// the body (before it appears, after the motion ended, or a clip where it is never visible) has
// empty x … v and visibility 0.
//
// Calibration files, so that the user's path is walked: boards/board_NN.png (chessboard views
// rendered by the same camera: POV-Ray, lens, vignetting, noise; 9 × 6 inner corners, 20 mm
// squares) for `uphill calibrate camera`, and points.csv (calibration/README.md's POINTS.csv:
// O, the rails at the crossbar, the posts' feet, the tape marks, each with its exact raw pixel in
// frame 0) with frame0.png for `uphill calibrate scene`; the true camera in camera_truth.json and
// scene_truth.json (frame 0's pose).
//
// Caching: a clip lives in <cache root>/<key>/ (FootageCacheRoot: ${XDG_CACHE_HOME:-~/.cache}/
// uphill/clips), the key a 64-bit FNV-1a hash of the condition's description (DescribeFootage,
// kept as condition.json beside the clip with the rendering time), which holds a digest of the
// generator's own code ("generator", src/footage/CMakeLists.txt); it is written under a private
// name and renamed into place when complete. RenderFootage reuses it unless asked for a fresh
// render. POV-Ray's pictures are cached too, in <cache root>/pictures/, keyed by their scene
// text: clips with the same camera, scene and motion (baseline, h265, flicker, ae-drift, the
// first second of two bad-input clips) render their sub-frames once. Any of it may be deleted.
#pragma once

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "vision/apparatus_points.hpp"
#include "vision/camera.hpp"
#include "vision/chessboard_render.hpp"
#include "footage/povray_render.hpp"
#include "footage/povray_scene.hpp"
#include "footage/sensor_model.hpp"
#include "footage/synthetic_clip.hpp"
#include "footage/video_encoder.hpp"

namespace uphill {

// Things that go wrong in a lab clip (the tracker must notice them, not invent positions).
struct FootageEvents {
  bool body_never_visible = false;  // the clip shows the apparatus without the body
  int camera_moves_at = -1;         // from this frame on, the camera has `moved_pose`
  CameraPose moved_pose;
  int exposure_changes_at = -1;     // from this frame on: exposure time and gain change
  double changed_exposure = 0;      // s
  double changed_gain = 1;
};

struct FootageCondition {
  std::string name;
  Scene scene = Scene(Body::Sphere(0.0254), Rails::FromApparatus(1.0, 0.1, 0.15, LConvention::kHorizontal), 0.004);
  FootageApparatus apparatus;
  FootageLook look;
  SceneCalibration camera;        // the true camera: intrinsics with distortion, and its pose
  double x0 = 0.25;               // release position, m
  double release_time = 0.3;      // s, clip time of the release
  MotionOptions motion;           // v0 (a push), μ (then kOde), g of the motion from x0
  int frames = 60;
  ShutterTiming shutter;          // fps, exposure, readout (height is the camera's)
  LightModel light;
  double gain = 1;                // sensor gain (exposure index) on the linear signal
  double vignetting = 0.5;        // s of (1 − s) + s·cos⁴θ
  SensorModel sensor;
  VideoCodec codec = VideoCodec::kH264;
  double bit_rate = 0;            // bits/s; 0: a phone's (PhoneBitRate)
  double max_step_px = 1.0;       // largest motion of a body point between sub-frames
  int max_subframes = 400;
  FootageEvents events;
  int boards = 14;                // chessboard views for the camera calibration
  ChessboardTarget board_target;  // 9 × 6 inner corners, 20 mm
  PovrayOptions povray;           // povray.threads caps each POV-Ray program's threads (+WT)
  // How many POV-Ray programs run at once. POV-Ray 3.7 idles ~0.2 s per picture in its own
  // polling loops, so several keep the cores busy; on a shared machine 1 (with povray.threads = 1)
  // keeps the render to one core. Neither changes a pixel (no jitter): not in the cache key.
  int povray_processes = 6;
};

// The description that keys the cache (everything that changes a pixel; JSON, SI units).
nlohmann::ordered_json DescribeFootage(const FootageCondition& condition);
std::string FootageKey(const FootageCondition& condition);  // 16 hex digits
std::string FootageCacheRoot();                             // ${XDG_CACHE_HOME:-$HOME/.cache}/uphill/clips

struct FootageFiles {
  std::string folder;
  std::string video;                  // clip.mp4 (H.264, H.265) or clip.mkv (FFV1)
  std::string truth_csv;              // truth.csv
  std::string points_csv;             // points.csv
  std::string first_frame;            // frame0.png
  std::string camera_truth, scene_truth;
  std::vector<std::string> boards;    // boards/board_NN.png
  bool from_cache = false;
  double render_wall_seconds = 0;     // when it was rendered (kept in condition.json)
  double render_cpu_seconds = 0;      // POV-Ray's and ours
  int povray_runs = 0, subframes = 0;  // POV-Ray runs (not counting pictures from the cache)
};

struct FootageProgress {
  std::function<void(const std::string& stage, int done, int total)> report;
};

// Renders the clip into <cache_root>/<key>/ or reuses it. Throws InputError for a condition that
// cannot be drawn (double cone, line rails, x0 outside the scene's path, frames < 1, exposure
// longer than the frame time, ...), std::runtime_error when povray or ffmpeg is missing or fails.
FootageFiles RenderFootage(const FootageCondition& condition, const std::string& cache_root,
                           bool fresh = false, const FootageProgress& progress = {});

// What rendering a condition asks of POV-Ray, found without rendering (render_clip --plan), for
// estimating a render's time from a sample's time per sub-frame: the sub-frames of each frame
// (a body at rest shares one picture over consecutive frames), and what is still to render, the
// pictures the picture cache holds (<cache root>/pictures) apart.
struct FootageFrameWork {
  int frame = 0;
  int subframes = 0;           // POV-Ray pictures of the body's windows in this frame
  int subframes_to_render = 0;
  double pixels_to_render = 0;
};
struct FootageWork {
  bool clip_cached = false;              // the whole clip is in the cache: nothing to render
  bool boards_cached = false;            // the chessboard views are
  int static_pictures = 0;               // whole pictures without the body, one per camera pose
  int static_to_render = 0;
  double static_pixels_to_render = 0;
  int runs_to_render = 0;                // POV-Ray runs of the body's windows
  int subframes = 0, subframes_to_render = 0;
  double pixels_to_render = 0;
  std::vector<FootageFrameWork> frames;
};
FootageWork PlanFootage(const FootageCondition& condition, const std::string& cache_root);

// The truth of a rendered clip (truth.csv). Throws InputError naming the file and row.
std::vector<ClipTruth> ReadFootageTruth(const std::string& path);

// The apparatus points of calibration/README.md (O, rails at the crossbar, feet, marks) with
// their exact raw pixels for this camera and pose, those in view (vision/apparatus_points.hpp).
std::vector<ApparatusPoint> FootageApparatusPoints(const FootageCondition& condition);

}  // namespace uphill
