// BallTracker: finds the body (sphere or spheroid) in the frames of a calibrated video, without
// clicks, and measures its centre to a small fraction of a pixel, also when it is smeared by a
// long exposure, sheared by a rolling shutter, painted, or seen against wood grain or cloth.
//
// What it uses (the camera and the apparatus stand still, only the body moves):
//  - linear light: each 8-bit value is decoded through the camera's transfer curve (sRGB unless
//    TrackerOptions::transfer says the video is linear) before anything else, since only there
//    is a blurred or anti-aliased edge a blend of body and background;
//  - the background: a per-pixel model of the band the body can sweep, learnt online from the
//    frames where the body is elsewhere, scaled by each frame's exposure gain
//    (internal/background_model.hpp);
//  - the body's own colours: the limb colour of each ray, solved in every fit, so that the
//    channel in which an edge is located is, ray by ray, the colour difference between the body
//    and what lies behind it (internal/outline_fit.hpp).
//
// Where it looks: only where the body can be. The first frame, and any frame after the body was
// lost, is searched along the projection of the scene's centre path x ↦ (x, 0, z(x)) for the
// predicted outlines whose inside differs most from their outside (from the background, once that
// is known) and those with the strongest grey step across them; a few are fitted per frame, places
// already refused whose pixels have not changed are skipped, and of the bodies found the one that
// stands out of its surroundings by the most noise levels is taken (one whose outline the edge fit
// finds all round before any other, then one where the edges it finds lie on the outline; such a
// body's contrast is weighed against the frame's noise, which its print does not raise; where
// the edge fit found the outline away from the model's fit, a print having pulled the model off
// the body, the contrast of the model fitted again from the outline counts), none by
// fewer than kAcquireMinStandOut (internal/tracker_thresholds.hpp). Where the edge fit found the
// outline and the model put the body elsewhere, the edge fit measures that frame. TrackerOptions::init_uv, a raw pixel near the centre,
// replaces that search for the first frame. Then frame by frame near the prediction from the last
// positions (constant acceleration in time). When a fit fails it re-acquires at once, in the same
// frame: along the path near the prediction, where a place more than a radius (and three frames'
// travel) off the prediction is not the body, then along the whole path. A centre beyond the path's ends
// [x_low, x_max] is never a body on the rails.
//
// The opening: a body at rest from the first frame hides the background under it, so the first
// frames are measured without it, and a mirror ball's reflections, a print or the table's grain
// can mislead them. The tracker keeps those frames (the band's bounding box, up to 256 MiB)
// until five frames in a row are found where the background confirms the body (inside the
// outline the pixels differ from it, just outside they match it). Finish() measures the opening
// again once the clip has shown the background: backwards from the first confirmed run to the
// first frame, each frame predicted from the two after it, and forwards over the frames after
// the run the background does not confirm. A frame found there that the background contradicts
// (not merely cannot judge, where it was never seen), and not found again, is withdrawn (a
// revision that says not found): the tracker does not report a position the pixels contradict.
//
// How it measures: the outline, smeared over the exposure. Under perspective a sphere of radius
// R centred at C projects to the boundary of the cone of rays at the angle asin(R/|C − O|) about
// the direction of C − O (O the camera centre); the spheroid (symmetry axis along y) is the same
// in the space where y is scaled by a/b. During the exposure the centre moves by D (fitted, with
// the prediction V·E as prior) along a path bent by the predicted acceleration (A = ½·a·E²: a ball
// speeding up spends longer near the start of its smear; without it the centre of a 3-radius
// blur came out 0.2 px ahead of the mid-exposure), so a pixel sees the body for a fraction of its exposure: the
// coverage of internal/smeared_outline.hpp, blurred by the optics' point spread. Rays from the
// predicted centre across the predicted smeared outline are sampled in linear light and the
// model I = (1 − c)·g·B + c·(F + h·G) (h the limb's shading profile √(2·depth/radius), G its
// amplitude per ray; c·S·F on a long smear, S the body's shading learnt at rest,
// lit by a lamp overhead whose distance is fitted frame by frame: internal/body_shading.hpp) is
// fitted with Ceres to all of them at once (centre and smear; per-ray Cauchy loss: a painted
// band's edges, highlights, the shadow and the crossbar do not fit one limb colour and drop
// out). The model's uniform edge shift (outline_fit.hpp) is held at 0 by every pass that places
// the centre: freed, it moved the centre across the motion. Rays through the near rail's band
// are not used. (u, v) is the projection of the fitted C, not the centre of the outline's
// ellipse, which perspective shifts.
//
// Model only what the scene needs (the fast path): most frames of most clips are a body that
// differs from its surroundings in luminance, moving less than a third of its radius during
// the exposure. There the outline's edges in linear luminance, fitted with Ceres (internal/edge_fit.hpp,
// one small solve), measure it as well as the model above at a fraction of the cost, so each
// frame near the prediction is first tried that way. The model takes over for the frame when
// the predicted smear is longer than 0.375 radius (half a radius while the exposure is only
// guessed), when a rolling shutter is set, when the
// edge fit lands more than 1 px + a tenth of the step from the prediction (the prediction's speed
// lagged, as just after the release: the blurred edge's ramp may then run off the search window
// and its truncated centroid lag toward the prediction), or when
// the edge fit is not trusted (edges found on less than 85 % of the rays, RMS above 0.3 px,
// luminance contrast below 20 levels of 255); and for the rest of the clip when the edge fit disagrees with
// the model where the body is found (by more than 0.5 px: a body as grey as its table, a painted
// body) or is distrusted three frames in a row. On the fast path the background is learnt every
// eighth frame (it is only needed when the model takes over). Where the model lacks the
// background under the body (it rested there since the first frame) and the edge fit is trusted
// and agrees within 1 px, the edge fit is reported until the background is seen.
//
// Time: the reported centre is at the mid-exposure of its frame (the container's timestamp for a
// global shutter). A rolling shutter (TrackerOptions::readout > 0: row r is exposed r·readout/H
// after row 0) shears the body: each ray's rows have their own window, and the centre is reported
// at the mid-exposure of the row where it lies, BallObservation::time_offset after the frame's
// timestamp. When the readout is unknown (TrackerOptions::measure_readout) it is measured from the
// outline's shear on the frames where the body moves fast enough for a whole frame's readout to
// shear it by a pixel: each such frame's fit gives the row delay its rays prefer (outline_fit.hpp,
// every parameter free) and, from five frames on, their median is used. Finish() settles it as
// the frames' inverse-variance mean, the frames fitted far from it fitted again there from
// windows kept of them, with its standard uncertainty (row_delay_settle.hpp; ReadoutEstimate()). The
// exposure time is a camera setting (TrackerOptions::exposure); when unknown it is measured from
// the fitted smear against the track's speed (ExposureEstimate()).
//
// Accuracy (tests/vision_track_test.cpp, tests/vision_povray_test.cpp, `uphill bench track`):
// see docs/track.md, "Accuracy"; the camera and scene calibration's own errors add to
// these on real video.
//
// Hard cases: the near rail hides the lower edge (masked); the body leaves the frame or drops
// between the rails (lost: found = false, quality 0; the next frames search the path again; a
// model fit whose outline's ends along the rods do not stand out of the table is not a body,
// internal/path_end_steps.hpp, since the rods' edges meet a disc anywhere between them); a
// frame with no body anywhere (not found, never invented: a body found anew before the background
// under it was seen, in the first frames, counts only once the next frames find it again near it;
// else it was the table's texture and is withdrawn by a revision); a double cone (refused). Where the
// body rested since the first frame the background under it is unknown until it leaves: those
// rays use a background constant along the ray, solved in the fit; while it stays where it was
// found, an edge fit that finds its outline all round where the model put it elsewhere (a
// striped or dotted print holds the model off the limb) measures it instead. A model fit a little
// off the rails' path is fitted again, freely and held on the path, and the held one replaces
// it where the pixels do not ask for the offset (its rim without contrast on one side:
// internal/tracker_measure.cpp, HeldOnPath). A centre measured
// off the rails' path (across it, beyond the calibration's error: internal/tracker_assess.cpp) is
// not reported unless the edge fit finds the outline on the path there (FramesLeftOffPath); the
// first frames, judged by a looser bound before the frames reported show the path's height, are
// judged again by that height when the clip ends (Finish), and withdrawn where they lie off it.
// A still track whose silhouette the background does not confirm (a place on the rods taken for
// a body at rest) gives way to a body it confirms elsewhere on the path (ConfirmedElsewhere).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <utility>
#include <vector>
#include <opencv2/core.hpp>

#include "model/scene.hpp"
#include "vision/camera.hpp"

namespace uphill {

// The one wording of the refusal of a double cone, whose outline the tracker does not fit (the
// quantity is "body"): the tracker, and before it every front end's use case, say it.
inline constexpr const char* kDoubleConeRefusal = "tracking supports a sphere or a spheroid, not a double cone";

enum class VideoTransfer { kSrgb, kLinear };

struct TrackerOptions {
  std::optional<Eigen::Vector2d> init_uv;  // raw pixel near the centre in the first frame
  int rays = 64;                           // rays across the outline per frame
  double search_half_width_px = 6;         // uncertainty of the prediction along each ray
  double rail_radius = 0.003;              // m: drawn width of line rails (scene without rods)
  double min_contrast = 0.03;              // body against background, linear light (0..1 per channel)
  // The camera (settings; see "Time" above).
  double fps = 30;                         // frames per second (the video's)
  std::optional<double> exposure;          // s; unset: measured from the smear
  double readout = 0;                      // s from the first to the last row; 0: global shutter
  bool measure_readout = false;            // a rolling shutter of unknown readout: measured (readout 0)
  VideoTransfer transfer = VideoTransfer::kSrgb;
  double point_spread_px = 0.7;            // σ of the optics' blur across an edge
  // A reported position of a quality (BallObservation::quality) below this is doubted, and left
  // out of the track where it lies off the motion of the frames around it
  // (video_tracking.hpp, TrackResult::frames_of_poor_fit). On random ray-traced scenes 4 of the
  // 20 frames below it were a pixel or more off (a print's edge, a blurred body half found), 1 of
  // the 2,912 above it; others below it were right (docs/track.md, "When it fails"). 0 doubts
  // none. The tracker itself only checks its range.
  double min_report_quality = 0.45;
};

struct BallObservation {
  bool found = false;
  double u = 0, v = 0;       // raw pixel of the fitted centre
  double radius_px = 0;      // mean distance of the outline from (u, v)
  double x = 0, z = 0;       // centre, m, apparatus frame
  double time_offset = 0;    // s after the frame's timestamp of the reported centre (rolling shutter)
  double smear_px = 0;       // length of the fitted smear over the exposure, px
  double quality = 0;        // [0, 1], 0 when not found (see ball_tracker.cpp, Quality)
  int rays = 0, inliers = 0; // rays fitted, rays that agree with the fit
  double misfit = 0;         // RMS residual of the inlier rays in units of the pixel noise
                             // (fast path: the edge points' RMS in units of 0.1 px)
  bool full_model = false;   // measured by the model (background, colours, smear), not the fast path
  // The centre's dependence on the part of the outline its edges came from, px (the edge fit's
  // sector spread, internal/edge_fit.hpp): a steady error that the frames at rest share. Stated
  // where the edge fit measured the frame; 0 where the model did (not stated).
  double outline_spread_px = 0;
};

class BallTracker {
 public:
  // Throws InputError for a double cone (quantity "body", kDoubleConeRefusal) or unusable
  // intrinsics or options.
  BallTracker(const Scene& scene, const SceneCalibration& calibration, const TrackerOptions& options = {});
  ~BallTracker();
  BallTracker(BallTracker&&) noexcept;

  // The next frame of the video (8-bit BGR or grey, the calibration's size; InputError otherwise).
  BallObservation Track(const cv::Mat& frame);

  // Frames measured before the background under the body was known (it rested there from the
  // first frame) or before its motion was (the first frames found) are measured again once they
  // are, from a window of the frame kept for that (a second pass over those windows only, not
  // over the video). The revised observations since the last call, by frame index; Finish()
  // measures the rest with what is known at the end of the video.
  std::vector<std::pair<long, BallObservation>> TakeRevisions();
  void Finish();

  // The raw-pixel outline of a body centred at (x, 0, z) (n points), e.g. to draw it.
  std::vector<Eigen::Vector2d> Outline(double x, double z, int n) const;

  // The exposure time measured so far from the smear against the speed (median over the frames
  // where the body moved more than 3 px), and how many frames it rests on; nullopt before any.
  struct Exposure {
    double seconds = 0;
    int frames = 0;
  };
  std::optional<Exposure> ExposureEstimate() const;

  // The rolling shutter's readout measured so far (TrackerOptions::measure_readout): s from the
  // first to the last row, and the frames it rests on; unset before five. During the clip it is
  // the median of the frames' estimates; after Finish() the least-squares readout of those frames
  // (see the header) and its standard uncertainty u: the mean's standard error and a systematic
  // 3 ms in quadrature, calibrated on the ray-traced clips (unset when it could not be settled).
  struct Readout {
    double seconds = 0;
    int frames = 0;
    std::optional<double> u;
  };
  std::optional<Readout> ReadoutEstimate() const;

  // Set when the picture outside the body changed beyond noise, lighting and exposure (the camera
  // moved, or the scene was disturbed) at this frame: the calibration no longer holds. The tracker
  // reports no positions from that frame on.
  std::optional<long> SceneChangedAt() const;
  // Frames whose measured centre lay off the rails' path, across it, by more than the
  // calibration's error, and whose outline the edge fit did not find on it: reported as not found
  // (a print's edge or a shadow taken for the outline; docs/track.md, "When it fails").
  long FramesLeftOffPath() const;
  // Frames where the exposure gain jumped (a step > 25 % between frames that stays).
  const std::vector<long>& ExposureChanges() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill
