// The tracker's predict stage and its bookkeeping (tracker_state.hpp): the motion through the
// last centres, the exposure and the row delay as measured so far, the body's region, and the
// watch for a changed scene or exposure.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "tracker_state.hpp"

namespace uphill {

double BallTracker::Impl::Exposure() const {
  if (options.exposure) return *options.exposure;
  if (exposures.size() >= 3) {
    std::vector<double> e = exposures;
    std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
    return e[e.size() / 2];
  }
  return 0.5 / options.fps;  // a 180° shutter, the usual default of video cameras
}

bool BallTracker::Impl::MeasuresReadout(const Vector2d& centre, const Vector2d& velocity) const {
  if (!options.measure_readout || row_delays.size() >= kReadoutFrames || velocity.isZero()) return false;
  const double px_per_s = velocity.norm() / MetresPerPx(centre.x(), centre.y());
  return px_per_s * 2 * RadiusPx(centre.x(), centre.y()) * FrameRowDelay() > 1;
}

bool BallTracker::Impl::MeasuredRowDelay(double delay) {
  if (!SeesShear(delay)) return false;
  row_delays.push_back(delay);
  if (row_delays.size() < kReadoutMinFrames) return true;
  std::vector<double> d = row_delays;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  SetRowDelay(std::clamp(d[d.size() / 2], 0.0, 0.999 * FrameRowDelay()));
  return true;
}

void BallTracker::Impl::SetRowDelay(double delay) {
  row_delay = delay;
  for (auto& [frame, s] : samples) s.t = s.frame_t + s.row * row_delay;
  for (auto& [frame, s] : history) s.t = s.frame_t + s.row * row_delay;
}

std::optional<internal::MotionFit> BallTracker::Impl::Motion(long f) const {
  if (history.empty() || f - history.back().first > kHistoryGap) return std::nullopt;
  std::vector<internal::TimedCentre> timed;
  for (const auto& [frame, s] : history) timed.push_back({s.t, Vector2d(s.x, s.z)});
  return internal::MotionFit::Through(timed);
}

cv::Rect BallTracker::Impl::BodyRegion(const Vector2d& centre, const Vector2d& smear) const {
  const Vector2d a = geometry.Project(centre.x() - 0.5 * smear.x(), centre.y() - 0.5 * smear.y());
  const Vector2d b = geometry.Project(centre.x() + 0.5 * smear.x(), centre.y() + 0.5 * smear.y());
  const double r = RadiusPx(centre.x(), centre.y()) * std::max(1.0, 1.0 / geometry.s);
  const double pad = 2 * r + 4;
  const int x0 = static_cast<int>(std::floor(std::min(a.x(), b.x()) - pad));
  const int y0 = static_cast<int>(std::floor(std::min(a.y(), b.y()) - pad));
  const int x1 = static_cast<int>(std::ceil(std::max(a.x(), b.x()) + pad));
  const int y1 = static_cast<int>(std::ceil(std::max(a.y(), b.y()) + pad + r));
  return cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & cv::Rect(0, 0, occluder.cols, occluder.rows);
}

void BallTracker::Impl::LearnShading(const cv::Mat& frame, const BallObservation& o, const Vector2d& velocity) {
  if (shading->ready() || history.size() < 3 || !o.found) return;
  if (velocity.norm() / options.fps / MetresPerPx(o.x, o.z) > 0.05) return;
  shading->Learn(frame, background->table(), geometry, o.x, o.z);
}

void BallTracker::Impl::Remember(long f, double t, const BallObservation& o) {
  // Found again from the unconfirmed frame's track (still in the history): confirmed.
  if (unconfirmed && f > unconfirmed->frame && !history.empty() && history.front().first <= unconfirmed->frame)
    unconfirmed.reset();
  samples[f] = SampleOf(t, o);
  history.emplace_back(f, samples[f]);
  if (history.size() > kHistory) history.pop_front();
}

namespace {
// The accepted centres of the frames within four of frame f (f's own left out), and how many of
// them lie before it.
std::vector<internal::TimedCentre> CentresAround(const std::map<long, BallTracker::Impl::Sample>& samples, long f,
                                                 int* before) {
  std::vector<internal::TimedCentre> near;
  *before = 0;
  for (auto it = samples.lower_bound(f - 4); it != samples.end() && it->first <= f + 4; ++it) {
    if (it->first == f) continue;
    near.push_back({it->second.t, Vector2d(it->second.x, it->second.z)});
    *before += it->first < f;
  }
  return near;
}
}  // namespace

bool BallTracker::Impl::VelocityAround(long f, double t, Vector2d* velocity, Vector2d* acceleration) const {
  int before = 0;
  const std::vector<internal::TimedCentre> near = CentresAround(samples, f, &before);
  const int after = static_cast<int>(near.size()) - before;
  if (before < 2 || after < 2) return false;
  const auto fit = internal::MotionFit::Through(near);
  if (!fit) return false;
  const internal::MotionState state = fit->At(t);
  *velocity = state.velocity;
  *acceleration = state.acceleration;
  return true;
}

std::optional<Vector2d> BallTracker::Impl::CentreAround(long f, double t) const {
  int before = 0;
  const std::vector<internal::TimedCentre> near = CentresAround(samples, f, &before);
  if (near.size() < 3) return std::nullopt;
  const auto fit = internal::MotionFit::Through(near);
  if (!fit) return std::nullopt;
  return fit->At(t).centre;
}

bool BallTracker::Impl::BackgroundKnownAround(const Vector2d& centre) const {
  const Vector2d q = geometry.Project(centre.x(), centre.y());
  const double r = RadiusPx(centre.x(), centre.y()) * std::max(1.0, 1.0 / geometry.s) + 8;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      const double x = q.x() + r * (2.0 * i / 11 - 1), y = q.y() + r * (2.0 * j / 11 - 1);
      if (x < 1 || y < 1 || x > occluder.cols - 3 || y > occluder.rows - 3) continue;
      if (background->InBand(x, y) && !background->Known(x, y)) return false;
    }
  return true;
}

void BallTracker::Impl::WatchScene(long f) {
  const double residual = background->SceneResidual();
  if (residual >= 0) {
    double usual = -1;
    if (scene_residuals.size() >= 5) {
      // The frames where the encoder copied the background tell nothing of its noise: the usual
      // level is that of the others, and nothing is judged before a few of them were seen.
      std::vector<double> r;
      for (double v : scene_residuals)
        if (v > 0) r.push_back(v);
      if (static_cast<int>(r.size()) >= kConfirmFrames) {
        std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
        usual = std::max(r[r.size() / 2], kUsualResidualFloor);
      }
    }
    if (usual > 0 && residual > kSceneChangeFactor * usual + 0.01) {
      if (scene_suspect++ == 0) scene_suspect_from = f;
      if (scene_suspect >= kConfirmFrames && !scene_changed_at) scene_changed_at = scene_suspect_from;
    } else {
      scene_suspect = 0;
      scene_residuals.push_back(residual);
      if (scene_residuals.size() > 30) scene_residuals.erase(scene_residuals.begin());
    }
  }
  gains.emplace_back(f, background->Gain());
  if (gains.size() > kConfirmFrames + 2) gains.pop_front();
  // A step between frames k−1 and k that the next frames keep.
  if (gains.size() == kConfirmFrames + 2) {
    const double before = gains[0].second, step_from = gains[1].second;
    bool holds = std::abs(std::log(step_from / before)) > std::log(1.25);
    for (size_t k = 2; k < gains.size() && holds; ++k) holds = std::abs(std::log(gains[k].second / step_from)) < std::log(1.1);
    if (holds && (exposure_changes.empty() || exposure_changes.back() < gains[1].first - kConfirmFrames))
      exposure_changes.push_back(gains[1].first);
  }
}

}  // namespace uphill
