// The tracker's measure stage (tracker_state.hpp): the outline fits and their observations.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "path_end_steps.hpp"
#include "tracker_state.hpp"

namespace uphill {

FitRequest BallTracker::Impl::Request(const Vector2d& centre, const Vector2d& velocity, bool moving_known, double half_width,
                   const Vector2d& acceleration) const {
  FitRequest q;
  q.centre = centre;
  q.velocity = velocity;
  q.rays = options.rays;
  q.noise = noise;
  q.light_inverse_distance = light_inverse_distance;
  q.half_width_px = half_width;
  q.row_delay = row_delay;
  q.estimate_row_delay = MeasuresReadout(centre, velocity);
  q.reference_row = geometry.Project(centre.x(), centre.y()).y();
  const double m_per_px = MetresPerPx(centre.x(), centre.y());
  if (moving_known) {
    q.smear = velocity * Exposure();
    q.bend = 0.5 * acceleration * Exposure() * Exposure();
    // How well the exposure is known: given, measured on enough frames, or the guess.
    const double relative = options.exposure ? 0.1 : exposures.size() >= 5 ? 0.15 : 0.5;
    q.smear_sigma = relative * q.smear.norm() + 0.5 * m_per_px;
  } else {
    // Nothing known of the motion yet (a body found for the first time is taken at rest; the
    // frames after it give its speed).
    q.smear = Vector2d::Zero();
    q.smear_sigma = 0.5 * m_per_px;
  }
  if (q.smear.norm() < 0.25 * m_per_px) q.smear = PathTangent(centre.x()) * 0.25 * m_per_px;
  return q;
}

bool BallTracker::Impl::EndsStandOut(const internal::FrameView& view, const FitOutcome& f, const FitRequest& q) const {
  const Vector2d c(f.p[internal::kCentreX], f.p[internal::kCentreZ]);
  const Vector2d at = geometry.Project(c.x(), c.y());
  // The rods' direction, not the centre path's: near the fall-off point the centre sinks between
  // the rods, and its path's direction in the picture points into them.
  const Vector2d along = Vector2d(1, scene.rails().tan_theta).normalized() * MetresPerPx(c.x(), c.y());
  const Vector2d tangent_px = (geometry.Project(c.x() + along.x(), c.y() + along.y()) - at).normalized();
  // The predicted smear, not the fitted one: a fit off the body may take any smear.
  const Vector2d smear_px = geometry.Project(c.x() + 0.5 * q.smear.x(), c.y() + 0.5 * q.smear.y()) -
                            geometry.Project(c.x() - 0.5 * q.smear.x(), c.y() - 0.5 * q.smear.y());
  const internal::PathEndSteps ends =
      internal::MeasurePathEndSteps(geometry, view, background->table(), c.x(), c.y(), tangent_px, smear_px);
  for (const double step : {ends.leading, ends.trailing})
    if (step >= 0 && step < kEndsMinStandOut * NoiseLevel(f)) return false;
  return true;
}

FitOutcome BallTracker::Impl::Measure(const internal::FrameView& view, FitRequest q, Search search,
                   int narrow_iterations) {
  // Every pass with the edge shift held: far from the edges it would rather shrink the outline
  // onto an inner edge than move it, and near them it moves the centre across the motion
  // (MeasureNear). The first pass again from where it went while it moves more
  // than a pixel and its last iteration still moved it by a pixel or more (the windows follow
  // a solve that had not settled; one that had moves by a fraction of a pixel when repeated; a
  // refit's single iteration has moved the whole way, so there the move alone decides), then a
  // narrow pass around the result. A body found anew is fitted again whenever it moved more than
  // a pixel: the repeat starts the smear afresh from its prior, where the first fit, far from the
  // edges, may have taken a spurious one (and then failed the inlier share a new body needs).
  q.fit_edge_shift = false;
  q.fit_light = false;
  q.limb_profile = search == Search::kTracking;
  // The row delay is read from the last pass only.
  const bool estimate_row_delay = q.estimate_row_delay;
  q.estimate_row_delay = false;
  FitOutcome first;
  for (int pass = 0; pass < 3; ++pass) {
    first = internal::FitOutline(geometry, view, *background, q);
    if (!first.ok) return first;
    const Vector2d moved = geometry.Project(first.p[internal::kCentreX], first.p[internal::kCentreZ]) -
                           geometry.Project(q.centre.x(), q.centre.y());
    q.centre = Vector2d(first.p[internal::kCentreX], first.p[internal::kCentreZ]);
    q.reference_row = geometry.Project(q.centre.x(), q.centre.y()).y();
    if (moved.norm() < 1.0 || (search == Search::kTracking && first.last_step_px < 1.0)) break;
    q.half_width_px = std::max(kNarrowHalfWidthPx + 1, 0.5 * q.half_width_px);
  }
  q.smear = Vector2d(first.p[internal::kSmearX], first.p[internal::kSmearZ]);
  q.estimate_row_delay = estimate_row_delay;
  q.fit_light = true;
  q.half_width_px = kNarrowHalfWidthPx;
  q.iterations = narrow_iterations;
  FitOutcome second = internal::FitOutline(geometry, view, *background, q);
  return second.ok ? second : first;
}

FitOutcome BallTracker::Impl::MeasureNear(const internal::FrameView& view, FitRequest q) {
  const FitRequest wide = q;
  q.half_width_px = kNarrowHalfWidthPx + 1;
  q.fit_edge_shift = false;
  q.iterations = kStartedNearIterations;
  const FitOutcome one = internal::FitOutline(geometry, view, *background, q);
  if (one.ok && (geometry.Project(one.p[internal::kCentreX], one.p[internal::kCentreZ]) -
                 geometry.Project(q.centre.x(), q.centre.y())).norm() < 0.5)
    return one;
  return Measure(view, wide);
}

// Both HeldOnPath's fits and OnPathWithoutLimb's start at the fit, in the narrow pass's windows,
// so that their costs compare.
static FitRequest StartedAt(const FitOutcome& fit, FitRequest q) {
  q.centre = Vector2d(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
  q.smear = Vector2d(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]);
  q.half_width_px = BallTracker::Impl::kNarrowHalfWidthPx;
  q.iterations = BallTracker::Impl::kHeldIterations;
  q.fit_edge_shift = false;
  q.estimate_row_delay = false;
  return q;
}

bool BallTracker::Impl::HeldOffPath(const FitOutcome& fit) const {
  const double height = std::abs(AcrossPathPx(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]));
  return fit.ok && height > kHeldFromPx && height <= kOnPathFirstPx;
}

std::optional<FitOutcome> BallTracker::Impl::OnPathWithoutLimb(const internal::FrameView& view, const FitOutcome& fit,
                                                               const FitRequest& q) const {
  if (!HeldOffPath(fit)) return std::nullopt;
  FitRequest plain = StartedAt(fit, q);
  plain.limb_profile = false;
  FitOutcome without = internal::FitOutline(geometry, view, *background, plain);
  if (!without.ok || std::abs(AcrossPathPx(without.p[internal::kCentreX], without.p[internal::kCentreZ])) > kHeldFromPx)
    return std::nullopt;
  without.row_delay = fit.row_delay, without.row_delay_sigma = fit.row_delay_sigma;
  return without;
}

FitOutcome BallTracker::Impl::HeldOnPath(const internal::FrameView& view, const FitOutcome& fit, FitRequest q) const {
  if (std::optional<FitOutcome> without = OnPathWithoutLimb(view, fit, q)) return *without;
  if (!HeldOffPath(fit)) return fit;
  const double x = fit.p[internal::kCentreX], z = fit.p[internal::kCentreZ];
  q = StartedAt(fit, q);
  const FitOutcome free = internal::FitOutline(geometry, view, *background, q);
  const double on = std::clamp(x, x_lo, x_hi);
  const PathPoint path = scene.At(on);
  q.path = internal::PathHold{on, path.z, path.dzdx, kHeldSigmaPx * MetresPerPx(x, z)};
  FitOutcome held = internal::FitOutline(geometry, view, *background, q);
  if (!free.ok || !held.ok) return fit;
  const double gain = (held.ray_cost - free.ray_cost) / std::max(1.0, free.misfit * free.misfit);
  if (gain >= kHeldSignificance) return fit;
  held.row_delay = fit.row_delay, held.row_delay_sigma = fit.row_delay_sigma;
  return held;
}

double BallTracker::Impl::Quality(const FitOutcome& f) const {
  const double fraction = std::min(1.0, static_cast<double>(f.inliers) / std::max(1, f.rays_tried));
  const double excess = std::max(0.0, f.misfit - 1.5);
  const double snr = f.contrast / std::max(noise, 1e-6);
  return fraction * std::exp(-0.5 * excess * excess) * std::min(1.0, snr / 20);
}

void BallTracker::Impl::Place(const Vector2d& centre, BallObservation* o) const {
  o->x = centre.x();
  o->z = centre.y();
  const Vector2d uv = geometry.Project(o->x, o->z);
  o->u = uv.x();
  o->v = uv.y();
  double sum = 0;
  for (const Vector2d& p : ProjectApparatusPoints(geometry.cal.camera, geometry.cal.pose, geometry.OutlinePoints(o->x, o->z, 32)))
    sum += (p - uv).norm();
  o->radius_px = sum / 32;
}

BallObservation BallTracker::Impl::Observe(const FitOutcome& f, const FitRequest& q) {
  BallObservation o;
  o.found = true;
  const Vector2d c_ref(f.p[internal::kCentreX], f.p[internal::kCentreZ]);
  // The reference time is the mid-exposure of row q.reference_row; report at the row where the
  // centre lies (fixed point: the row moves by |dv/dt|·delay ≪ 1 row per iteration).
  Vector2d c = c_ref;
  double offset = 0;
  if (row_delay > 0) {
    for (int it = 0; it < 3; ++it) {
      const double row = geometry.Project(c.x(), c.y()).y();
      offset = row * row_delay;
      c = c_ref + q.velocity * ((row - q.reference_row) * row_delay);
    }
  }
  Place(c, &o);
  o.time_offset = offset;
  o.smear_px = SmearPx(c_ref, Vector2d(f.p[internal::kSmearX], f.p[internal::kSmearZ]));
  o.rays = f.rays_fitted;
  o.inliers = f.inliers;
  o.misfit = f.misfit;
  o.quality = Quality(f);
  o.full_model = true;
  return o;
}

BallObservation BallTracker::Impl::ObserveEdges(const internal::EdgeFitOutcome& e) const {
  BallObservation o;
  o.found = true;
  Place(Vector2d(e.x, e.z), &o);
  o.rays = e.edge_points;
  o.inliers = e.inliers;
  o.misfit = e.rms_px / 0.1;  // in units of a good edge fit's scatter
  const double fraction = std::min(1.0, static_cast<double>(e.inliers) / std::max(1, e.attempted));
  o.quality = fraction * std::exp(-e.rms_px * e.rms_px / (2 * 0.25));
  o.full_model = false;
  o.outline_spread_px = internal::SectorSpreadPx(geometry, e);
  return o;
}

}  // namespace uphill
