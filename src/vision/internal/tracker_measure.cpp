// The tracker's measure and acquire stages (tracker_state.hpp): the outline fits, their
// observations, and the candidates along the path where the body is looked for anew.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

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

std::vector<Vector2d> BallTracker::Impl::Candidates(const cv::Mat& frame, double gain, double x0, double x1) const {
  x0 = std::max(x0, x_lo);
  x1 = std::min(x1, x_hi);
  if (!(x1 > x0)) return {};
  const int n = 32;
  // Candidates a quarter radius apart in the image.
  const Vector2d p0 = geometry.Project(x0, scene.At(x0).z), p1 = geometry.Project(x1, scene.At(x1).z);
  const double r_mid = RadiusPx(0.5 * (x0 + x1), scene.At(0.5 * (x0 + x1)).z);
  const int count = std::clamp(static_cast<int>((p1 - p0).norm() / std::max(1.0, 0.25 * r_mid)) + 1, 8, 2000);
  std::vector<std::pair<double, double>> scored;  // (score, x)
  std::vector<cv::Vec3f> inside(n), outside(n);
  for (int i = 0; i < count; ++i) {
    const double xc = x0 + (x1 - x0) * (i + 0.5) / count;
    const double zc = scene.At(xc).z;
    if (!WithinLens(geometry.cal.pose.rotation * Vector3d(xc, 0, zc) + geometry.cal.pose.translation)) continue;
    std::vector<Vector3d> pts = geometry.OutlinePoints(xc, zc, n);
    pts.emplace_back(xc, 0, zc);
    const std::vector<Vector2d> image = ProjectApparatusPoints(geometry.cal.camera, geometry.cal.pose, pts);
    const Vector2d q = image[n];
    int used = 0;
    std::vector<double> bg_in, bg_out;
    for (int k = 0; k < n; ++k) {
      const Vector2d dir = (image[k] - q).normalized();
      const double r = (image[k] - q).norm();
      const Vector2d pin = image[k] - 0.4 * r * dir, pout = image[k] + 3.0 * dir;
      bool ok = std::min({pin.x(), pin.y(), pout.x(), pout.y()}) >= 1 && std::max(pin.x(), pout.x()) < frame.cols - 2 &&
                std::max(pin.y(), pout.y()) < frame.rows - 2;
      ok = ok && !occluder.at<std::uint8_t>(static_cast<int>(pout.y() + 0.5), static_cast<int>(pout.x() + 0.5));
      if (!ok) continue;
      inside[used] = internal::SampleLinear(frame, background->table(), pin.x(), pin.y());
      outside[used] = internal::SampleLinear(frame, background->table(), pout.x(), pout.y());
      if (background->Known(pin.x(), pin.y()) && background->Known(pout.x(), pout.y())) {
        bg_in.push_back(cv::norm(inside[used] - background->At(pin.x(), pin.y()) * gain));
        bg_out.push_back(cv::norm(outside[used] - background->At(pout.x(), pout.y()) * gain));
      }
      ++used;
    }
    if (used < n / 2) continue;
    double score;
    if (static_cast<int>(bg_in.size()) >= used * 3 / 4) {
      // Inside differs from the background, outside does not.
      std::nth_element(bg_in.begin(), bg_in.begin() + bg_in.size() / 2, bg_in.end());
      std::nth_element(bg_out.begin(), bg_out.begin() + bg_out.size() / 2, bg_out.end());
      score = bg_in[bg_in.size() / 2] - bg_out[bg_out.size() / 2];
    } else {
      // The inside's median colour against each outside sample: a body of one colour on any
      // surroundings gives a consistent step.
      cv::Vec3f median_in;
      std::vector<float> channel(used);
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < used; ++k) channel[k] = inside[k][c];
        std::nth_element(channel.begin(), channel.begin() + used / 2, channel.end());
        median_in[c] = channel[used / 2];
      }
      std::vector<double> steps(used);
      for (int k = 0; k < used; ++k) steps[k] = cv::norm(median_in - outside[k]);
      std::nth_element(steps.begin(), steps.begin() + used / 4, steps.end());
      score = steps[used / 4];  // the lower quartile: the step must hold nearly all round
    }
    scored.emplace_back(score, xc);
  }
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Vector2d> out;
  for (const auto& [score, xc] : scored) {
    if (score < options.min_contrast || out.size() >= 3) break;
    // Distinct candidates: at least a radius apart.
    const Vector2d p = geometry.Project(xc, scene.At(xc).z);
    bool near = false;
    for (const Vector2d& o : out) near = near || (geometry.Project(o.x(), o.y()) - p).norm() < RadiusPx(xc, scene.At(xc).z);
    if (!near) out.emplace_back(xc, scene.At(xc).z);
  }
  return out;
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
  const Vector2d smear(f.p[internal::kSmearX], f.p[internal::kSmearZ]);
  o.smear_px = (geometry.Project(c_ref.x() + 0.5 * smear.x(), c_ref.y() + 0.5 * smear.y()) -
                geometry.Project(c_ref.x() - 0.5 * smear.x(), c_ref.y() - 0.5 * smear.y()))
                   .norm();
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
  return o;
}

}  // namespace uphill
