// The tracker's assess-and-revise stage (tracker_state.hpp): frames kept until the background
// under the body and its motion are known, then fitted again; the readout settled at the end of
// the clip; a body found once and never again withdrawn.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "tracker_state.hpp"

namespace uphill {

void BallTracker::Impl::KeepForRefit(long f, double t, const cv::Mat& frame, double gain, const FitOutcome& fit,
                  const BallObservation& o, bool motion_known, bool edge_fallback) {
  if (fit.rays_without_background == 0 && motion_known) return;
  const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
  const Vector2d smear(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]);
  const cv::Rect box = KeptWindow(c, smear * 2, frame);
  if (box.empty()) return;
  constexpr size_t kPendingBytes = 256u << 20;  // enough for minutes of a body at rest
  const size_t bytes = box.area() * 3u;
  if (pending_bytes + bytes > kPendingBytes) return;
  pending.push_back({f, t, gain, frame(box).clone(), box.tl(), o, c, edge_fallback});
  pending_bytes += bytes;
}

cv::Rect BallTracker::Impl::KeptWindow(const Vector2d& centre, const Vector2d& smear, const cv::Mat& frame) const {
  const cv::Rect box = BodyRegion(centre, smear);
  return cv::Rect(box.x - 24, box.y - 24, box.width + 48, box.height + 48) & cv::Rect(0, 0, frame.cols, frame.rows);
}

void BallTracker::Impl::KeepReadoutFrame(const cv::Mat& frame, double gain, const FitOutcome& fit, FitRequest q) {
  q.centre = Vector2d(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
  q.reference_row = geometry.Project(q.centre.x(), q.centre.y()).y();
  q.half_width_px = kNarrowHalfWidthPx;
  // The edge shift free here alone: this refit places no centre, and the shear it measures
  // shows at the smear's ends, where the edge shift acts.
  q.fit_edge_shift = q.fit_light = true;
  q.iterations = kStartedNearIterations;
  q.light_inverse_distance = fit.light_inverse_distance;
  q.estimate_row_delay = true;
  const cv::Rect box = KeptWindow(q.centre, 2 * Vector2d(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]), frame);
  if (!box.empty())
    readout_frames.push_back({frame(box).clone(), box.tl(), gain, q, {fit.row_delay, fit.row_delay_sigma}});
}

void BallTracker::Impl::SettleReadout() {
  if (readout_frames.size() < kReadoutMinFrames) return;
  std::vector<internal::FrameFit> fits;
  std::vector<double> fitted_at;
  for (const ReadoutFrame& k : readout_frames) fits.push_back(k.estimate), fitted_at.push_back(k.request.row_delay);
  auto refit = [&](size_t i, double q) -> internal::FrameFit {
    const ReadoutFrame& k = readout_frames[i];
    FitRequest r = k.request;
    r.row_delay = q;
    const FitOutcome fit = internal::FitOutline(geometry, {k.window, k.origin, k.gain}, *background, r);
    if (fit.ok && fit.row_delay_sigma > 0 && SeesShear(fit.row_delay))
      return internal::FrameDelay{fit.row_delay, fit.row_delay_sigma};
    return std::nullopt;
  };
  const double most = 0.999 * FrameRowDelay();
  if (const auto settled = internal::SettleRowDelay(fits, fitted_at, kReadoutNear * FrameRowDelay(), most,
                                                    kReadoutMinFrames, refit)) {
    SetRowDelay(settled->delay);
    row_delay_u = std::hypot(settled->u, kReadoutSystematic / geometry.cal.camera.height);
    row_delay_frames = settled->frames;
  }
}

void BallTracker::Impl::FitAgain(bool all) {
  for (auto it = pending.begin(); it != pending.end();) {
    Vector2d velocity, acceleration;
    const bool motion = VelocityAround(it->frame, it->t, &velocity, &acceleration);
    const bool background_known = BackgroundKnownAround(it->centre);
    const bool ready = (motion || all) && (all || background_known);
    if (!ready) {
      ++it;
      continue;
    }
    // Where the background under the body was never seen the model's per-ray background is
    // less sure than the edge fit that stood in for it.
    if (it->edge_fallback && !background_known) {
      pending_bytes -= it->window.total() * it->window.elemSize();
      it = pending.erase(it);
      continue;
    }
    if (!motion) velocity = acceleration = Vector2d::Zero();
    // Started at the frame's own fit, within a pixel or so; or, where the frames around it put
    // the body more than a pixel from it (the search's fit in a body's first frame, started
    // far off), where they put it.
    Vector2d start = it->centre;
    if (const std::optional<Vector2d> around = CentreAround(it->frame, it->t);
        around && (geometry.Project(around->x(), around->y()) - geometry.Project(start.x(), start.y())).norm() > 1)
      start = *around;
    FitRequest q = Request(start, velocity, motion, kNarrowHalfWidthPx + 1.5, acceleration);
    q.iterations = kStartedNearIterations;
    q.estimate_row_delay = false;  // measured when the frame was first fitted
    const internal::FrameView view{it->window, it->origin, it->gain};
    FitOutcome fit = Measure(view, q, Search::kTracking, kStartedNearIterations);
    if (std::optional<FitOutcome> without = OnPathWithoutLimb(view, fit, q)) fit = *without;
    if (Accept(fit, 0.45)) {
      BallObservation o = Observe(fit, q);
      const double moved = std::hypot(o.u - it->observed.u, o.v - it->observed.v);
      if (moved < 0.5 * RadiusPx(o.x, o.z)) {
        revisions.emplace_back(it->frame, o);
        samples[it->frame] = SampleOf(it->t, o);
      }
    }
    pending_bytes -= it->window.total() * it->window.elemSize();
    it = pending.erase(it);
  }
}

void BallTracker::Impl::Withdraw() {
  const long k = unconfirmed->frame;
  revisions.emplace_back(k, BallObservation{});
  samples.erase(k);
  for (auto it = pending.begin(); it != pending.end();) {
    if (it->frame != k) {
      ++it;
      continue;
    }
    pending_bytes -= it->window.total() * it->window.elemSize();
    it = pending.erase(it);
  }
  std::erase_if(history, [k](const auto& h) { return h.first == k; });
  needs_model = unconfirmed->needs_model_before;
  unconfirmed.reset();
}

}  // namespace uphill
