// BallTracker's set-up, its public interface, and Track: one frame through the stages (predict,
// measure or acquire, assess), whose parts live in internal/tracker_*.cpp (tracker_state.hpp).
#include "vision/ball_tracker.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <opencv2/imgproc.hpp>

#include "internal/near_rail_band.hpp"
#include "internal/tracker_state.hpp"
#include "model/input_error.hpp"

namespace uphill {

BallTracker::BallTracker(const Scene& scene, const SceneCalibration& calibration, const TrackerOptions& options)
    : impl_(std::make_unique<Impl>(scene, options)) {
  ValidateIntrinsics(calibration.camera, "camera");
  const Body& body = scene.body();
  if (body.kind == BodyKind::kDoubleCone)
    throw InputError("body", kDoubleConeRefusal);
  if (options.rays < 16 || options.rays > 1024) throw InputError("rays", "must be in 16..1024");
  if (!(options.search_half_width_px >= 2 && options.search_half_width_px <= 200))
    throw InputError("search_half_width_px", "must be in [2, 200] px");
  if (!(options.fps > 0 && std::isfinite(options.fps))) throw InputError("fps", "must be > 0");
  if (options.exposure && !(*options.exposure > 0 && *options.exposure <= 1.0 / options.fps * 1.0001))
    throw InputError("--exposure", "must be > 0 and at most the frame time 1/fps");
  if (!(options.readout >= 0 && options.readout < 1.0 / options.fps))
    throw InputError("--readout", "must be >= 0 and below the frame time 1/fps");
  if (options.measure_readout && options.readout > 0)
    throw InputError("--readout", "give the readout or have it measured (auto), not both");
  if (!(options.point_spread_px >= 0.2 && options.point_spread_px <= 5))
    throw InputError("point_spread_px", "must be in [0.2, 5] px");
  if (!(options.min_report_quality >= 0 && options.min_report_quality <= 1))
    throw InputError("--min-quality", "must be in [0, 1]");
  Impl& m = *impl_;
  internal::OutlineGeometry& g = m.geometry;
  g.cal = calibration;
  g.a = body.across;
  g.s = body.across / body.along;
  g.eye = CameraCentre(calibration.pose);
  g.eye_s = Vector3d(g.eye.x(), g.s * g.eye.y(), g.eye.z());
  g.to_apparatus = calibration.pose.rotation.transpose();
  g.sigma_px = options.point_spread_px;
  m.row_delay = options.readout / calibration.camera.height;
  const double span = scene.x_max() - scene.x_low();
  m.x_lo = scene.x_low() + 1e-6 * span;
  m.x_hi = scene.x_max() - 1e-6 * span;

  // The near rail (on the camera's side) in front of the body: its band in the image.
  const int width = calibration.camera.width, height = calibration.camera.height;
  m.lens_reach = LensModelReach(calibration.camera);
  m.occluder = internal::DrawNearRailBand(scene, g, scene.rod_radius() > 0 ? scene.rod_radius() : options.rail_radius,
                                          [&m](const Vector3d& pc) { return m.WithinLens(pc); }, m.x_lo, m.x_hi);
  g.occluder = &m.occluder;
  m.shading = std::make_unique<internal::BodyShading>(g.s);
  g.shading = m.shading.get();
  m.edges = std::make_unique<internal::EdgeFit>(
      m.geometry, Impl::kEdgePoints, options.transfer == VideoTransfer::kLinear ? internal::Transfer::kLinear : internal::Transfer::kSrgb);

  // The band the body can sweep: discs along the centre path, a radius and a margin wider than
  // the body (the rays reach beyond the outline), for the background model.
  cv::Mat band = cv::Mat::zeros(height, width, CV_8U);
  const int steps = 2000;
  cv::Point last_at(-1 << 30, 0);
  int last_radius = -1;
  for (int i = 0; i <= steps; ++i) {
    const double x = m.x_lo + (m.x_hi - m.x_lo) * i / steps;
    const double z = scene.At(x).z;
    const Vector3d cam = calibration.pose.rotation * Vector3d(x, 0, z) + calibration.pose.translation;
    if (cam.z() <= 2 * g.a || !m.WithinLens(cam)) continue;
    const Vector2d q = g.Project(x, z);
    if (std::abs(q.x()) > 4 * width || std::abs(q.y()) > 4 * height) continue;
    const double r = m.RadiusPx(x, z) * std::max(1.0, 1.0 / g.s);
    const cv::Point at(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())));
    const int radius = static_cast<int>(std::ceil(1.6 * r + 16));
    if (at == last_at && radius == last_radius) continue;  // the same disc again
    cv::circle(band, at, radius, cv::Scalar(255), cv::FILLED);
    last_at = at, last_radius = radius;
  }
  m.background = std::make_unique<internal::BackgroundModel>(
      std::move(band), options.transfer == VideoTransfer::kLinear ? internal::Transfer::kLinear : internal::Transfer::kSrgb);
}

BallTracker::~BallTracker() = default;
BallTracker::BallTracker(BallTracker&&) noexcept = default;

std::vector<Vector2d> BallTracker::Outline(double x, double z, int n) const {
  return ProjectApparatusPoints(impl_->geometry.cal.camera, impl_->geometry.cal.pose, impl_->geometry.OutlinePoints(x, z, n));
}

std::optional<BallTracker::Exposure> BallTracker::ExposureEstimate() const {
  if (impl_->exposures.empty()) return std::nullopt;
  return Exposure{impl_->Exposure(), static_cast<int>(impl_->exposures.size())};
}

std::optional<BallTracker::Readout> BallTracker::ReadoutEstimate() const {
  if (impl_->row_delays.size() < Impl::kReadoutMinFrames) return std::nullopt;
  const double rows = impl_->geometry.cal.camera.height;
  Readout r;
  r.seconds = impl_->row_delay * rows;
  r.frames = static_cast<int>(impl_->row_delays.size());
  if (impl_->row_delay_u) {
    r.u = *impl_->row_delay_u * rows;
    r.frames = impl_->row_delay_frames;
  }
  return r;
}

std::optional<long> BallTracker::SceneChangedAt() const { return impl_->scene_changed_at; }
long BallTracker::FramesLeftOffPath() const { return impl_->left_off_path; }

std::vector<std::pair<long, BallObservation>> BallTracker::TakeRevisions() {
  std::vector<std::pair<long, BallObservation>> out;
  out.swap(impl_->revisions);
  impl_->AssessRevisions(&out);
  return out;
}

void BallTracker::Finish() {
  Impl& m = *impl_;
  m.SettleReadout();
  m.FitAgain(true);
  if (m.unconfirmed && m.frame_index > m.unconfirmed->frame) m.Withdraw();
  m.RecoverOpening();
  m.RejudgeProvisionalFrames();
}
const std::vector<long>& BallTracker::ExposureChanges() const { return impl_->exposure_changes; }

BallObservation BallTracker::Track(const cv::Mat& input) {
  Impl& m = *impl_;
  const BallObservation o = m.Track(input);
  cv::Mat bgr;
  if (input.channels() == 1) cv::cvtColor(input, bgr, cv::COLOR_GRAY2BGR);
  const cv::Mat& frame = input.channels() == 1 ? bgr : input;
  if (!m.opening_closed && !m.scene_changed_at) m.KeepOpening(m.frame_index, m.frame_index / m.options.fps, frame, o);
  return m.Assess(frame, o);
}

BallObservation BallTracker::Impl::Track(const cv::Mat& input) {
  Impl& m = *this;
  if (input.empty() || input.depth() != CV_8U || (input.channels() != 1 && input.channels() != 3))
    throw InputError("frame", "must be an 8-bit grey or BGR image");
  const CameraIntrinsics& camera = m.geometry.cal.camera;
  if (input.cols != camera.width || input.rows != camera.height)
    throw InputError("frame", "is " + std::to_string(input.cols) + "x" + std::to_string(input.rows) +
                                  " px but the camera calibration is for " + std::to_string(camera.width) + "x" +
                                  std::to_string(camera.height));
  cv::Mat converted;
  if (input.channels() == 1) cv::cvtColor(input, converted, cv::COLOR_GRAY2BGR);
  const cv::Mat& frame = input.channels() == 1 ? converted : input;
  const long f = ++m.frame_index;
  const double t = f / m.options.fps;

  // The reference time: the mid-exposure of the row where the centre lies at that time.
  std::optional<internal::MotionState> motion;
  if (const auto fit = m.Motion(f)) {
    motion = fit->AtOwnRow(t, m.row_delay, [&](const Vector2d& c) { return m.geometry.Project(c.x(), c.y()).y(); });
    if (!motion->centre.allFinite() || !motion->velocity.allFinite()) motion.reset();
  }
  const bool predicted = motion.has_value();
  if (m.unconfirmed && !predicted) m.Withdraw();  // not found again while it could be predicted
  Vector2d centre, velocity, acceleration;
  if (predicted) centre = motion->centre, velocity = motion->velocity, acceleration = motion->acceleration;
  cv::Rect region;
  if (predicted) region = m.BodyRegion(centre, velocity * m.Exposure());
  m.background->Measure(frame, region);
  m.WatchScene(f);
  const double gain = m.background->Gain();
  if (m.scene_changed_at) return {};

  // A frame the model measured. `acquired`: the body was found anew (not near the prediction).
  // `outline`: an edge fit that found a body's outline where the model, without the background,
  // put it elsewhere (the acquisition below); it measures the frame.
  auto finish = [&](const FitOutcome& measured, const FitRequest& q, bool acquired,
                    const std::optional<internal::EdgeFitOutcome>& outline = std::nullopt) {
    const FitOutcome fit = outline ? measured : m.HeldOnPath({frame, {0, 0}, gain}, measured, q);
    const bool needs_model_before = m.needs_model;
    BallObservation o = m.Observe(fit, q);
    m.light_inverse_distance = fit.light_inverse_distance;
    if (fit.row_delay_sigma > 0 && m.MeasuredRowDelay(fit.row_delay)) m.KeepReadoutFrame(frame, gain, fit, q);
    m.noises.push_back(std::clamp(fit.noise, 1e-3, 0.2));
    if (m.noises.size() > 15) m.noises.pop_front();
    std::vector<double> sorted(m.noises.begin(), m.noises.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    m.noise = sorted[sorted.size() / 2];
    const bool confident = fit.misfit < 1.5 && fit.inliers >= kExposureMinAgreement * fit.rays_fitted;
    if (fit.rays_without_background == 0) m.confident_model_frame = f;
    const Vector2d fitted_velocity = q.velocity;
    const Vector2d smear(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]);
    // The exposure, from the smear against the track's speed (where the body moved > 3 px).
    const double step_px = fitted_velocity.norm() / m.options.fps / m.MetresPerPx(o.x, o.z);
    if (!m.options.exposure && confident && m.history.size() >= 3 && step_px > 3) {
      const double e = smear.dot(fitted_velocity) / fitted_velocity.squaredNorm();
      if (e > 0 && e < 1.5 / m.options.fps) m.exposures.push_back(e);
    }
    const bool motion_known = q.smear_sigma > 0.5 * m.MetresPerPx(o.x, o.z) * 1.01 || m.history.size() >= 2;
    // The edge fit at the model's centre: at acquisition it says whether this clip can take the
    // fast path (grey contrast, no pattern near the outline: it agrees with the model); where the
    // background under the body was never seen it stands in for the model until it is.
    bool edge_fallback = false;
    auto measured_by_edges = [&](const internal::EdgeFitOutcome& e) {
      const double offset = o.time_offset;
      o = m.ObserveEdges(e);
      o.time_offset = offset;
      edge_fallback = true;
    };
    if (outline) {
      m.needs_model = true;  // the edge fit and the model disagree: not a clip for the fast path
      measured_by_edges(*outline);
    } else if (acquired || fit.rays_without_background > 0) {
      if (acquired) m.edges->Reset();
      const internal::EdgeFitOutcome e = m.edges->Measure(frame, o.x, o.z, kNarrowHalfWidthPx + 1);
      const double apart = e.ok ? (m.geometry.Project(e.x, e.z) - Vector2d(o.u, o.v)).norm() : 1e9;
      const bool agrees = m.Trusted(e) && apart < kFastMaxDisagreementPx + (fit.rays_without_background > 0 ? 0.5 : 0);
      if (acquired && !agrees) m.needs_model = true;
      if (fit.rays_without_background > 0 && agrees) {
        measured_by_edges(e);
      } else if (const Vector2d found_px = m.geometry.Project(m.found_at.x(), m.found_at.y());
                 fit.rays_without_background > 0 && (m.geometry.Project(q.centre.x(), q.centre.y()) - found_px).norm() < kAtRestPx) {
        // A body at rest whose background was never seen: the model has only the body's inside
        // to go by, and a print (stripes, dots) can hold its outline off the body or bias it by a
        // few tenths of a pixel. The contrast at the outline alone then measures it, where it
        // finds a clean outline all round, still where the body was found (and predicted there).
        const internal::EdgeFitOutcome w = m.edges->Measure(frame, o.x, o.z, 2 * m.options.search_half_width_px);
        const Vector2d at = m.geometry.Project(w.x, w.z);
        if (m.CleanOutline(w) && (at - found_px).norm() < kAtRestPx)
          measured_by_edges(w);
      }
    }
    if (acquired) m.found_at = Vector2d(o.x, o.z);
    m.LearnShading(frame, o, q.velocity);
    m.Remember(f, t, o);
    if (m.history.size() == 1 && fit.rays_without_background > 0) {
      if (m.unconfirmed) m.Withdraw();
      m.unconfirmed = Impl::Unconfirmed{f, needs_model_before};
    }
    m.KeepForRefit(f, t, frame, gain, fit, o, motion_known, edge_fallback);
    // Not while a scene change is being confirmed: the changed picture is not the background.
    // Near the body (what it uncovered since the last frame, and where the next frames' rays
    // read) where the model learnt the frame before; the whole band every kLearnEvery frames, as
    // on the fast path, and after any frame it did not learn (the body found anew, or measured
    // by the fast path): a still scene's background needs no more looks than that, normalised by
    // each frame's gain.
    if (m.scene_suspect == 0) {
      const Vector2d held = edge_fallback ? Vector2d(o.x, o.z) : Vector2d(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
      const cv::Rect body = m.BodyRegion(held, smear);
      const int reach = static_cast<int>(std::ceil(2 * m.RadiusPx(o.x, o.z) + step_px)) + 2;
      const cv::Rect near(body.x - reach, body.y - reach, body.width + 2 * reach, body.height + 2 * reach);
      const bool whole = f % kLearnEvery == 0 || m.learnt_near_at != f - 1;
      m.background->Learn(frame, body, whole ? cv::Rect() : near);
      m.learnt_near_at = f;
    }
    m.FitAgain(false);
    return o;
  };

  // A still track the background cannot confirm, and a body it confirms elsewhere: the track was
  // something else (a place on the rods, kept out of the background's learning since), and the
  // body is that one. Looked at as often as the whole band is learnt (kLearnEvery), within half
  // a radius of where the track was found: a fit on a rod wanders by a few pixels.
  if (predicted && f % kLearnEvery == 0 &&
      (m.geometry.Project(centre.x(), centre.y()) - m.geometry.Project(m.found_at.x(), m.found_at.y())).norm() <
          0.5 * m.RadiusPx(centre.x(), centre.y()))
    if (const std::optional<Impl::Found> elsewhere = m.ConfirmedElsewhere(frame, gain, centre)) {
      m.history.clear();
      m.rejected.Clear();
      return finish(elsewhere->fit, elsewhere->request, true);
    }

  // The fast path: the edge fit, where the scene does not need the model (see the header).
  if (predicted && !m.needs_model && m.row_delay == 0 && !m.MeasuresReadout(centre, velocity)) {
    const double px = 1 / m.MetresPerPx(centre.x(), centre.y());
    // With the exposure not yet known, and the body's shading known (so that the model measures
    // a long smear better than the edge fit), the blur is taken at its longest (a 360° shutter):
    // a longer blur than the fast path allows biases its edges (0.6 px on the first moving frames
    // of a shaded ball under a 360° shutter), and the model measures the exposure meanwhile.
    // Otherwise it is guessed (180°), and the edge fit's own checks decide up to a longer limit.
    const bool exposure_known = m.options.exposure || m.exposures.size() >= 3;
    const bool cautious = !exposure_known && m.shading->ready();
    const double exposure = cautious ? 1 / m.options.fps : m.Exposure();
    const double blur_px = velocity.norm() * exposure * px, step_px = velocity.norm() / m.options.fps * px;
    const double limit = exposure_known || cautious ? kFastMaxBlur : kFastMaxBlurGuessed;
    if (blur_px <= limit * m.RadiusPx(centre.x(), centre.y())) {
      const internal::EdgeFitOutcome e =
          m.edges->Measure(frame, centre.x(), centre.y(), m.options.search_half_width_px + 0.3 * step_px);
      const double off = e.ok ? (m.geometry.Project(e.x, e.z) - m.geometry.Project(centre.x(), centre.y())).norm() : 1e9;
      // Where the prediction missed by more than its usual error (the body just released, or
      // speeding up faster than the last frames said), the edge's ramp may be longer than the
      // blur predicted, run off the search window, and its truncated centroid lag toward the
      // prediction (0.7 px at 10 px per frame under a 360° shutter): the model measures the frame.
      const bool blur_holds = off < 1.0 + 0.1 * step_px;
      const bool trusted = m.Trusted(e) && m.OnPath(e.x, e.z) &&
                           off < std::max(4.0, 0.5 * m.RadiusPx(centre.x(), centre.y()) + step_px);
      if (trusted && blur_holds) {
        m.distrusted = 0;
        const BallObservation o = m.ObserveEdges(e);
        m.LearnShading(frame, o, velocity);
        m.Remember(f, t, o);
        if (f % kLearnEvery == 0 && m.scene_suspect == 0) m.background->Learn(frame, m.BodyRegion(Vector2d(e.x, e.z), velocity * m.Exposure()));
        m.FitAgain(false);
        return o;
      }
      if (!trusted && ++m.distrusted >= kFastDistrust) m.needs_model = true;
    }
  }
  if (predicted) {
    const double step_px = velocity.norm() / m.options.fps / m.MetresPerPx(centre.x(), centre.y());
    const FitRequest q = m.Request(centre, velocity, m.history.size() >= 2,
                                   m.options.search_half_width_px + 0.3 * step_px, acceleration);
    const FitOutcome fit = m.confident_model_frame == f - 1 && m.history.size() >= 3
                               ? m.MeasureNear({frame, {0, 0}, gain}, q)
                               : m.Measure({frame, {0, 0}, gain}, q);
    // Far from the prediction is a jump to something else unless the search confirms it.
    const double off = (m.geometry.Project(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]) -
                        m.geometry.Project(centre.x(), centre.y())).norm();
    if (m.Accept(fit, 0.45) && off < std::max(4.0, 0.5 * m.RadiusPx(centre.x(), centre.y()) + step_px) &&
        m.EndsStandOut({frame, {0, 0}, gain}, fit, q))
      return finish(fit, q, false);
  }
  // (Re)acquire: near the prediction, else along the whole path.
  std::optional<Impl::Prediction> near;
  if (predicted) near = Impl::Prediction{centre, velocity, acceleration};
  if (const std::optional<Impl::Found> found = m.Acquire(frame, gain, f, near))
    return finish(found->fit, found->request, found->anew, found->outline);
  // Predicted past the path's ends (beyond the fall-off point the rails no longer carry it,
  // before x_low it has reached O) and not found: it fell or was taken off, and following its
  // prediction further costs full-model fits of an empty scene. The search along the path still
  // runs every frame.
  const bool off_the_path = predicted && (centre.x() > m.x_hi || centre.x() < m.x_lo);
  if (!predicted || off_the_path) m.history.clear();
  return {};
}

}  // namespace uphill
