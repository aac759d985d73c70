// BallTracker::Impl: the tracker's state between frames and its stages, private to the tracker.
// The stages live in their own files:
//   ball_tracker.cpp          set-up, the public interface, and Track: one frame through the stages
//   tracker_motion.cpp        predict: the motion through the last centres, the exposure, the row
//                             delay, the body's region, and the scene-change watch
//   tracker_acquire.cpp       acquire: the places along the path where the body is looked for
//                             anew (Candidates), and the search that fits them (Acquire)
//   tracker_measure.cpp       measure: the outline fits (two passes, or one near a good
//                             prediction) and their observations
//   tracker_refit.cpp         assess and revise: frames kept for a refit once the background and
//                             the motion are known, the readout settled at the end, a body withdrawn
//   tracker_opening.cpp       the clip's opening: its frames measured again at the end, backwards
//                             from the first ones the background confirms
//   tracker_assess.cpp        the last look at a position before it is reported: on the path?
// Thresholds: tracker_thresholds.hpp.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "background_model.hpp"
#include "body_shading.hpp"
#include "edge_fit.hpp"
#include "motion_prediction.hpp"
#include "outline_fit.hpp"
#include "rejected_windows.hpp"
#include "row_delay_settle.hpp"
#include "tracker_thresholds.hpp"
#include "vision/ball_tracker.hpp"

namespace uphill {

// The tracker's files share these names (this header is private to them).
using Eigen::Vector2d;
using Eigen::Vector3d;
using internal::FitOutcome;
using internal::FitRequest;

struct BallTracker::Impl : internal::TrackerThresholds {
  struct Sample {
    double t, x, z;  // s (clip time of the reported centre), m
    // The frame's time and the centre's row: under a rolling shutter t is frame_t + row·δ, δ the
    // rows' delay as known now (the samples are re-timed whenever it changes).
    double frame_t = 0, row = 0;
  };

  // Whether a search follows the body (a prediction or a frame's own fit to start from) or
  // looks for it anew.
  enum class Search { kTracking, kAcquiring };

  Scene scene;
  TrackerOptions options;
  internal::OutlineGeometry geometry;
  cv::Mat occluder;                                 // CV_8U: the near rail's band
  std::unique_ptr<internal::BackgroundModel> background;
  std::unique_ptr<internal::BodyShading> shading;   // learnt from the first frames at rest
  double light_inverse_distance = 0;                // 1/m: its lamp's, in the last model fit
  std::deque<std::pair<long, Sample>> history;      // last found (frame, sample)
  long frame_index = -1;
  double x_lo = 0, x_hi = 0;                        // searchable part of the path
  double lens_reach = 0;                            // LensModelReach of the camera
  double noise = 0.01;                              // residual RMS of a sample, linear units
  std::deque<double> noises;                        // of the last accepted frames
  std::deque<double> across_path;                   // AcrossPathPx of the last frames reported
  long left_off_path = 0;                           // frames not reported for lying off the path
  std::deque<double> left_heights;                  // AcrossPathPx of the frames left out in a row
  // x (m) of the last frame reported within kOnPathPx of the calibrated path: where a body was
  // seen on it, a height off it is the fit's, not the calibration's (Assess).
  std::optional<double> on_path_x;
  // A frame reported before the path's height was known: one of the first, or one of the
  // kOnPathFrames reported from an adopted height on (kOnPathAdoptFrames). Its height is kept as
  // revised since.
  struct Provisional {
    long frame;
    double height;  // AcrossPathPx
    bool adopted;
  };
  std::vector<Provisional> provisional;
  std::size_t adopted_left = 0;  // frames still to be reported as provisional since a height was adopted
  double row_delay = 0;                             // s per row
  std::vector<double> exposures;                    // per-frame measurements |D|/|V|
  std::vector<double> row_delays;                   // per-frame measurements of the row delay, s
  // The frames that measured the row delay: a window of each, its last fit's request (made at
  // request.row_delay) and that fit's estimate; the far ones fitted again at the end of the clip
  // (SettleReadout).
  struct ReadoutFrame {
    cv::Mat window;
    cv::Point origin;
    double gain;
    FitRequest request;
    internal::FrameDelay estimate;
  };
  std::vector<ReadoutFrame> readout_frames;
  std::optional<double> row_delay_u;                // s per row, once settled
  int row_delay_frames = 0;                         // the frames it was settled on
  std::vector<double> scene_residuals;              // recent steady levels
  int scene_suspect = 0;
  long scene_suspect_from = -1;
  std::optional<long> scene_changed_at;
  std::deque<std::pair<long, double>> gains;        // (frame, gain)
  // Every accepted frame's centre (revised ones included), for the velocity at a past frame.
  std::map<long, Sample> samples;
  // Frames measured before the background under the body or its motion was known: a window of
  // the frame each, fitted again once both are (FitAgain), their revised observations handed out
  // by TakeRevisions.
  struct Pending {
    long frame;
    double t, gain;
    cv::Mat window;
    cv::Point origin;
    BallObservation observed;
    Vector2d centre;  // fitted, at the reference time
    bool edge_fallback = false;  // observed by the edge fit: keep it unless the background becomes known
  };
  std::deque<Pending> pending;
  size_t pending_bytes = 0;
  std::vector<std::pair<long, BallObservation>> revisions;
  std::vector<long> exposure_changes;
  // Fast path: the edge fit; whether this clip needs the full model on every frame (its grey
  // contrast is low, its body patterned, or the edge fit keeps failing), and why.
  std::unique_ptr<internal::EdgeFit> edges;
  bool needs_model = false;
  int distrusted = 0;
  Vector2d found_at = Vector2d::Zero();  // the centre where the body was last found anew, m
  long confident_model_frame = -1;  // the last frame the model measured, its background known
  long learnt_near_at = -1;         // the last frame whose background the model's path learnt
  // A body found anew where the model could not check it against the background (rays whose
  // background was never seen: the first frames of a clip) counts once the next frames find it
  // again near it; found in that frame alone it was the table's texture (wood grain between the
  // rails), not a body, and it is withdrawn (a revision that says not found).
  struct Unconfirmed {
    long frame;
    bool needs_model_before;
  };
  std::optional<Unconfirmed> unconfirmed;
  // The clip's opening: each frame (the band's bounding box) from the first until the body has
  // been found in kOpeningAnchorFrames frames in a row that the background confirms
  // (SilhouetteOf). A body at rest from the first frame hides the background under it, so
  // those frames are measured without it and may lock onto the body's reflections, its print or
  // the table; once the body has moved away the background is known, and Finish() measures the
  // opening again, backwards from that run (RecoverOpening).
  struct OpeningFrame {
    long frame;
    double t, gain;
    cv::Mat window;
    cv::Point origin;
    BallObservation observed;  // as reported so far (revisions applied)
  };
  std::vector<OpeningFrame> opening;
  size_t opening_bytes = 0;
  bool opening_closed = false;
  int opening_confirmed_run = 0;

  // The whole-path search's candidates fitted and rejected since the body was last found, with
  // their pixels (see rejected_windows.hpp).
  internal::RejectedWindows rejected;

  Impl(const Scene& sc, const TrackerOptions& o) : scene(sc), options(o) {}

  double Exposure() const;

  // Whether this frame's fit measures the row delay (TrackerOptions::measure_readout): until
  // kReadoutFrames have, where a whole frame's readout would shear the body by over a pixel.
  bool MeasuresReadout(const Vector2d& centre, const Vector2d& velocity) const;

  // A frame's measured row delay; the median of all so far is used from kReadoutMinFrames on.
  // False for a fit that did not see the shear (a delay far outside one frame time's).
  bool MeasuredRowDelay(double delay);
  // A centre reported in the frame of time t, at the time of its row with the rows' delay as now
  // known (its time_offset, unless the delay changed since it was measured).
  Sample SampleOf(double t, const BallObservation& o) const { return Sample{t + o.v * row_delay, o.x, o.z, t, o.v}; }
  // The rows' delay from here on, and the times of the centres measured so far with it: those
  // measured before it was known (at a global shutter's 0, the first five) lie several pixels
  // off the motion of those after, and the prediction from both would miss by as much.
  void SetRowDelay(double delay);
  bool SeesShear(double delay) const { return delay > -0.5 * FrameRowDelay() && delay < 1.5 * FrameRowDelay(); }
  // The row delay of a readout lasting the whole frame time, s per row: the most a camera has.
  double FrameRowDelay() const { return 1 / options.fps / geometry.cal.camera.height; }

  double RadiusPx(double x, double z) const {
    const Vector3d c(x, 0, z);
    return geometry.a * geometry.cal.camera.fx / (c - geometry.eye).norm();
  }
  double MetresPerPx(double x, double z) const { return 1.0 / (geometry.cal.camera.fx / (Vector3d(x, 0, z) - geometry.eye).norm()); }

  // The motion through the history (motion_prediction.hpp), while the body may still be predicted
  // from it.
  std::optional<internal::MotionFit> Motion(long f) const;

  // The length in the picture of a smear (x, z), m, centred at `centre`, px.
  double SmearPx(const Vector2d& centre, const Vector2d& smear) const {
    return (geometry.Project(centre.x() + 0.5 * smear.x(), centre.y() + 0.5 * smear.y()) -
            geometry.Project(centre.x() - 0.5 * smear.x(), centre.y() - 0.5 * smear.y()))
        .norm();
  }
  // The body's region (smeared silhouette, a radius around it, and its shadow below it), px.
  cv::Rect BodyRegion(const Vector2d& centre, const Vector2d& smear) const;

  // The path's direction at x (unit, (x, z)).
  Vector2d PathTangent(double x) const {
    const double slope = scene.At(std::clamp(x, x_lo, x_hi)).dzdx;
    return Vector2d(1, slope).normalized();
  }

  // `acceleration` bends the smear over the exposure (smeared_outline.hpp); zero when unknown.
  FitRequest Request(const Vector2d& centre, const Vector2d& velocity, bool moving_known, double half_width,
                     const Vector2d& acceleration = Vector2d::Zero()) const;

  // A fit's noise level: the clip's, once a frame was accepted; before that the fit's own
  // residual RMS where larger (see Accept).
  double NoiseLevel(const FitOutcome& f) const { return noises.empty() ? std::max(noise, f.noise) : noise; }
  // A fit is a body when enough rays agree with it, the body stands out of the background by
  // several noise levels, and its inlier rays fit within a few noise levels. `agreement`: the
  // share of the fitted rays that must be inliers (less near the prediction, where a painted
  // body's band or the rails may cost rays, than for a body found anew); and 10 rays at least, a
  // quarter of those fitted (the rays in view): the near rail hides up to two thirds of a body
  // between thick rods (a chrome ball with 22 rays in view, 14 of them on its outline within
  // 0.2 px of the truth, was refused in all its frames by a floor of a quarter of all rays).
  // Before any frame was accepted the clip's noise is not known (`noise` is a guess, and a 1080p
  // phone clip's is three times it): the levels are then the fit's own residual RMS, so that a
  // body found where it is is not refused for the guess. And the centre must lie on the path
  // (OnPath).
  bool Accept(const FitOutcome& f, double agreement) const { return Accept(f, agreement, NoiseLevel(f)); }
  // The same at a given noise level, the body standing out of the background by `levels` of it.
  bool Accept(const FitOutcome& f, double agreement, double level, double levels = kAcceptMinLevels) const {
    const double misfit = f.misfit * noise / level;
    return f.ok && f.inliers >= std::max(10.0, 0.25 * f.rays_fitted) && f.inliers >= agreement * f.rays_fitted &&
           f.contrast >= options.min_contrast && f.contrast >= levels * level && misfit < 3 &&
           OnPath(f.p[internal::kCentreX], f.p[internal::kCentreZ]);
  }
  // Whether the fitted outline's ends along the rods (path_end_steps.hpp) each stand out of what
  // lies beyond them by kEndsMinStandOut noise levels (the levels Accept takes), where the
  // picture shows them: the rods' edges run along the path and meet a disc anywhere between
  // them, so only the ends say that a body is there.
  bool EndsStandOut(const internal::FrameView& view, const FitOutcome& f, const FitRequest& q) const;
  // Whether a centre lies on the rails' range [x_low, x_max], within a pixel: beyond x_max the
  // body has fallen between the rails, and a fit there is the table where it was (the background
  // under it never seen), not the body.
  bool OnPath(double x, double z) const {
    const double pixel = MetresPerPx(x, z);
    return x > scene.x_low() - pixel && x < scene.x_max() + pixel;
  }

  // A centre's height above the calibrated path at its x, in pixels at the body's distance.
  double AcrossPathPx(double x, double z) const;
  // Whether a centre lies across the path where the body can be. A body on the rails has its
  // centre on the path, so a position off it by more than the calibration's error is a fit that
  // took a print's edge, a shadow or a rod for the outline (kOnPathPx). A calibration that puts
  // the path farther off is followed: a centre near the median height of the last frames
  // reported lies on it too (kOnPathUsualPx), and before kOnPathMinFrames were, one within
  // kOnPathFirstPx of the path.
  bool OnPathAcross(double x, double z) const;
  // The same for a centre `height` px across the path (AcrossPathPx).
  bool HeightOnPath(double height) const;
  // The median height of the last frames reported (across_path, not empty), px.
  double UsualHeight() const;
  // A frame's position as reported (the tracker's own state keeps what it measured): o where it
  // lies on the path; else the edge fit's, where that finds the body's outline on the path; else
  // not found (counted in left_off_path), unless the frames left out in a row say that the
  // calibration puts the path that far off (kOnPathAdoptFrames) and no frame was reported on the
  // calibrated path within a body radius of this one (on_path_x): a body cannot change its
  // height on the rails where it is, so there the offset is the fit's (a striped ball at rest
  // behind a thick rod, found on the path in its first frame, was then fitted 5.9 px below it,
  // and that height was adopted for 23 frames).
  BallObservation Assess(const cv::Mat& frame, const BallObservation& o);
  // The revisions that may be reported: a revised position off the path leaves the frame's row
  // as it was. The provisional frames among them take their revised height (or leave the list,
  // withdrawn).
  void AssessRevisions(std::vector<std::pair<long, BallObservation>>* revised);
  // At the end of the clip, the provisional frames judged again by the usual height of the last
  // frames reported: one off it is withdrawn. The first kOnPathMinFrames (more than kOnPathPx off
  // the path, while kOnPathFirstPx was the bound) always; the kOnPathFrames reported from an
  // adopted height on only where the last frames lie on the calibrated path (within kOnPathPx):
  // the adoption was then a fit held off a body at rest at one height for ten frames (a chrome
  // ball's reflections), not a calibration that far off, whose offset may change along the path.
  void RejudgeProvisionalFrames();

  // Two passes: around the guess with the given half width, then narrow around the first fit
  // (with `narrow_iterations`; q.iterations caps the first passes).
  FitOutcome Measure(const internal::FrameView& view, FitRequest q, Search search = Search::kTracking,
                     int narrow_iterations = kNarrowIterations);

  // One narrow pass, where the prediction is good (the model measured the previous frame, its
  // background known): one Ceres solve instead of two or more. Measure() when the fit moves more
  // than half a pixel from the prediction or fails. The edge shift is held as in Measure(), so
  // that both fit the same parameters: freed here alone, it moves the centre across the motion
  // on fast frames.
  FitOutcome MeasureNear(const internal::FrameView& view, FitRequest q);
  // `fit` (of request q), or where it lies off the calibrated path by kHeldFromPx to
  // kOnPathFirstPx, the fit held on the path unless the pixels ask for the offset
  // (tracker_thresholds.hpp): a rim without contrast on one side lets the outline slide across.
  // OnPathWithoutLimb first.
  FitOutcome HeldOnPath(const internal::FrameView& view, const FitOutcome& fit, FitRequest q) const;
  // A fit kHeldFromPx to kOnPathFirstPx off the calibrated path (HeldOffPath), fitted again
  // without the limb's shading profile (outline_fit.hpp), where that fit lies within kHeldFromPx
  // of the path; else nothing. The profile refines a matte body's limb; a glossy limb mirrors the
  // rods and the table, and the profile then holds the outline off the path (a ball at rest
  // drifted 2.8 px off it in its first frames; its fits without the profile within 0.2 px).
  std::optional<FitOutcome> OnPathWithoutLimb(const internal::FrameView& view, const FitOutcome& fit,
                                              const FitRequest& q) const;
  bool HeldOffPath(const FitOutcome& fit) const;

  // Whether the lens model maps the camera-frame point where it is (LensModelReach).
  bool WithinLens(const Vector3d& pc) const { return pc.z() > 0 && pc.head<2>().norm() < lens_reach * pc.z(); }

  // The motion's prediction for a frame: centre (x, z) at its reference time, m; velocity, m/s;
  // acceleration, m/s².
  struct Prediction {
    Vector2d centre, velocity, acceleration;
  };
  // A body found by the search: its fit and request, the edge fit that measures it instead
  // (a body whose outline the edge fit found where the model, without the background, put it
  // elsewhere), and whether
  // it was found anew (not near the prediction).
  struct Found {
    FitOutcome fit;
    FitRequest request;
    std::optional<internal::EdgeFitOutcome> outline;
    bool anew = false;
  };
  // The search: the initial guess in frame 0 (TrackerOptions::init_uv), the candidates near the
  // prediction `near` (the first one accepted is the body), else along the whole path (one whose
  // outline the edge fit finds, then the one that stands out of its surroundings by the most
  // noise levels). Clears the history when the body is found anew or far from the prediction.
  std::optional<Found> Acquire(const cv::Mat& frame, double gain, long f, const std::optional<Prediction>& near);
  // A body the background confirms (SilhouetteOf) away from the still one tracked at `tracked`,
  // whose silhouette it does not: a place on the rods or the table taken for a body at rest keeps
  // the background under it from ever being learnt, while the body rolls elsewhere. The search
  // along the path skips the places within two radii of `tracked` and fits up to
  // kAcquireFitsPerFrame of the others; the first accepted whose silhouette the background
  // confirms is the body, found anew.
  std::optional<Found> ConfirmedElsewhere(const cv::Mat& frame, double gain, const Vector2d& tracked);

  // A place to start a fit at, and a second start where a fit from the first does not find a
  // body (the centre of a colour candidate's plateau).
  struct SearchStart {
    Vector2d at;
    std::optional<Vector2d> again;
  };
  // Candidates along the path between x0 and x1: the best kCandidatesByColour by the predicted
  // outline's inside against its outside (against the background where it is known), then the
  // best kCandidatesByStep by the grey step across the outline.
  std::vector<SearchStart> Candidates(const cv::Mat& frame, double gain, double x0, double x1) const;
  // The centre of the plateau of colour scores ((score, x) in x order) around the place x = peak.
  static double PlateauCentre(const std::vector<std::pair<double, double>>& along, double peak);
  // Where the plateau's centre lies within a quarter radius of its highest place, a print's dot or
  // a highlight may still have lifted the place beside the body's centre above the one on it, and
  // a fit started a quarter radius off on a large body can miss it: the neighbour on the plateau
  // is the second start.
  static std::optional<double> PlateauNeighbour(const std::vector<std::pair<double, double>>& along, double peak);

  // Quality in [0, 1]: the share of the visible outline's rays that agree with the fit, lowered
  // when those fit worse than the pixel noise allows and when the body stands out of the
  // background by less than 20 noise levels.
  double Quality(const FitOutcome& f) const;

  // The centre (x, z), its pixel and the outline's mean radius about it.
  void Place(const Vector2d& centre, BallObservation* o) const;

  BallObservation Observe(const FitOutcome& f, const FitRequest& q);

  // The fit whose contrast says how much a body found anew stands out: `fit`, or where the edge
  // fit found its outline `outline` elsewhere and the model fitted again from the outline's
  // centre stands out by more there, that fit.
  FitOutcome ContrastAtOutline(const cv::Mat& frame, double gain, const internal::EdgeFitOutcome& outline,
                               const FitOutcome& fit);

  // The fast path's fit is trusted when it saw the outline nearly all round, in grey-level
  // contrast well above the noise, and its edge points lie on the fitted outline.
  bool Trusted(const internal::EdgeFitOutcome& e) const {
    return e.ok && e.inliers >= 0.35 * kEdgePoints && e.inliers >= kFastMinAgreement * e.attempted &&
           e.contrast >= kFastMinContrast && e.rms_px <= kFastMaxRmsPx;
  }

  BallObservation ObserveEdges(const internal::EdgeFitOutcome& e) const;

  // An edge fit whose edges, where it found them, lie on the body's outline: most of them within
  // a pixel of it (kOutlineFoundShare), or most of the rays searched with half of all the rays at
  // least (kOutlineMostRays); their scatter below half a pixel, in contrast well above the noise.
  // Looser than CleanOutline: a print's stripes hide the limb's grey step on a third of the rays,
  // or put a stronger edge beside it on a quarter of them, but not the outline's place.
  // min_contrast: grey levels (kFastMinContrast; a sharp outline found anew may be fainter,
  // kAcquireFaintContrast).
  bool OutlineFound(const internal::EdgeFitOutcome& e, double min_contrast = kFastMinContrast) const {
    const bool most_found = e.inliers >= kOutlineFoundShare * e.edge_points;
    const bool most_rays = e.inliers >= kOutlineMostRays * kEdgePoints && e.inliers >= kOutlineMostSearched * e.attempted;
    return e.ok && e.inliers >= 0.35 * kEdgePoints && (most_found || most_rays) && e.contrast >= min_contrast &&
           e.rms_px <= kCleanOutlineRmsPx;
  }

  // An edge fit that found edges of a body's contrast on part of the outline, nearly all of them
  // on it (kOutlinePartialPoints at least): a grey body on a grey cloth shows its edge on half of
  // its outline only, where a patch of the cloth's texture has no edge that strong.
  bool OutlinePartlyFound(const internal::EdgeFitOutcome& e) const {
    return e.ok && e.inliers >= kOutlinePartialPoints && e.inliers >= kOutlineFoundShare * e.edge_points &&
           e.contrast >= kFastMinContrast && e.rms_px <= kCleanOutlineRmsPx;
  }

  // An outline found (OutlineFound) with nearly every edge on it and their scatter within the fast
  // path's: sharp enough that a body found anew needs to stand out less (kAcquireMinStandOutSharp).
  bool SharpOutline(const internal::EdgeFitOutcome& e) const {
    return OutlineFound(e) && e.inliers >= kSharpOutlineShare * e.edge_points && e.rms_px <= kFastMaxRmsPx;
  }

  // An outline found (OutlineFound) in a contrast from kAcquireFaintContrast grey levels, its
  // edges scattered by kFastMaxRmsPx at most: a body in dim light, at acquisition.
  bool FaintOutlineFound(const internal::EdgeFitOutcome& e) const {
    return OutlineFound(e, kAcquireFaintContrast) && e.rms_px <= kFastMaxRmsPx;
  }

  // An edge fit that found the body's outline all round: most of its rays within a pixel of it,
  // their scatter below half a pixel, in contrast well above the noise. Looser than Trusted (the
  // fast path's check, which must also hold where the model would do better): it only decides
  // between the edge fit and a model fit that has no background to go by.
  bool CleanOutline(const internal::EdgeFitOutcome& e) const {
    return e.ok && e.inliers >= 0.35 * kEdgePoints && e.inliers >= kCleanOutlineAgreement * e.attempted &&
           e.contrast >= kFastMinContrast && e.rms_px <= kCleanOutlineRmsPx;
  }

  // A frame where the body rests (found near a prediction that barely moves) is a sharp view of
  // its shading.
  void LearnShading(const cv::Mat& frame, const BallObservation& o, const Vector2d& velocity);

  void Remember(long f, double t, const BallObservation& o);

  // The velocity and acceleration at time t of frame f from the accepted centres of the frames
  // around it (a parabola in time through up to four on each side); false with fewer than two on
  // each side.
  bool VelocityAround(long f, double t, Vector2d* velocity, Vector2d* acceleration) const;
  // The centre at time t of frame f from the accepted centres of the frames around it (up to four
  // on each side, three at least on either); nullopt with fewer.
  std::optional<Vector2d> CentreAround(long f, double t) const;

  // Whether the background is known everywhere around the body centred at `centre` (its region,
  // on a 12 × 12 lattice of the band's pixels).
  bool BackgroundKnownAround(const Vector2d& centre) const;

  // Keeps a window of the frame for a refit when the fit lacked the background or the motion.
  void KeepForRefit(long f, double t, const cv::Mat& frame, double gain, const FitOutcome& fit,
                    const BallObservation& o, bool motion_known, bool edge_fallback);

  // The part of a frame kept for a later fit: the body's region, 24 px more each side (a fit
  // started there may move by that much).
  cv::Rect KeptWindow(const Vector2d& centre, const Vector2d& smear, const cv::Mat& frame) const;

  // A frame that measured the row delay, for SettleReadout: the window its smear covers, the
  // request of a narrow pass from its fit, and its estimate. The smear's prior stays the motion's
  // prediction: one centred on the smear fitted at this frame's delay would hold part of the
  // shear that delay got wrong.
  void KeepReadoutFrame(const cv::Mat& frame, double gain, const FitOutcome& fit, FitRequest q);

  // The clip's row delay, settled on the frames that measured it (row_delay_settle.hpp), and its
  // standard uncertainty; the running median of their estimates is kept when it cannot be.
  void SettleReadout();

  // Fits kept frames again whose background and motion are now known (all of them when `all`,
  // with whatever is known by then).
  void FitAgain(bool all);

  void Withdraw();

  // What the background says of a body whose outline is centred at `centre`: it confirms it
  // when the pixels inside differ from the background as a body's must and those just outside
  // match it; it contradicts it when they do not (a fit on the table's texture or on a
  // reflection); it cannot decide where the background is unknown under too much of either.
  // `smear_px`: the body's smear over the exposure, along the path (BallObservation::smear_px).
  enum class Silhouette { kConfirms, kContradicts, kUndecided };
  Silhouette SilhouetteOf(const internal::FrameView& view, const Vector2d& centre, double smear_px) const;
  // The smear of frame f's observation, px: fitted, or (the fast path fits none) the step to a
  // neighbouring frame's centre over the exposure.
  double SmearOf(long f, const BallObservation& o) const;
  // Keeps this frame for the opening while it lasts (after Track measured it as `o`).
  void KeepOpening(long f, double t, const cv::Mat& frame, const BallObservation& o);
  // At Finish(): the opening measured again, backwards from its first confirmed run (without
  // one, only its frames not found, backwards from its first run found and not contradicted);
  // each frame whose observation changes (found, moved, or withdrawn) becomes a revision.
  void RecoverOpening();

  // Scene residual and gain bookkeeping (SceneChangedAt, ExposureChanges).
  void WatchScene(long f);

  // One frame through the stages (BallTracker::Track).
  BallObservation Track(const cv::Mat& input);
};

}  // namespace uphill
