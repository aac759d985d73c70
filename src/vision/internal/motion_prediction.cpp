#include "motion_prediction.hpp"

#include <Eigen/QR>
#include <cmath>

namespace uphill::internal {

std::optional<MotionFit> MotionFit::Through(const std::vector<TimedCentre>& samples) {
  if (samples.empty()) return std::nullopt;
  const size_t n = samples.size();
  MotionFit fit;
  fit.degree_ = n >= 4 ? 2 : n >= 2 ? 1 : 0;
  // Times from the last sample: the polynomial's terms stay of the size of a frame's.
  fit.t0_ = samples.back().t;
  Eigen::MatrixXd a(n, fit.degree_ + 1), y(n, 2);
  for (size_t i = 0; i < n; ++i) {
    const double dt = samples[i].t - fit.t0_;
    double power = 1;
    for (int k = 0; k <= fit.degree_; ++k, power *= dt) a(i, k) = power;
    y.row(i) = samples[i].c.transpose();
  }
  fit.coef_.topRows(fit.degree_ + 1) = a.colPivHouseholderQr().solve(y);
  if (!fit.coef_.allFinite()) return std::nullopt;
  return fit;
}

MotionState MotionFit::At(double t) const {
  const double dt = t - t0_;
  MotionState s{t, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  s.centre = coef_.row(0).transpose() + dt * coef_.row(1).transpose() + dt * dt * coef_.row(2).transpose();
  s.velocity = coef_.row(1).transpose() + 2 * dt * coef_.row(2).transpose();
  s.acceleration = 2 * coef_.row(2).transpose();
  return s;
}

MotionState MotionFit::AtOwnRow(double frame_t, double row_delay,
                                const std::function<double(const Eigen::Vector2d&)>& row) const {
  MotionState s = At(frame_t);
  if (row_delay == 0) return s;
  // Each step shrinks the time's error by the map's contraction (see the header); it stops once a
  // step moves the time by less than 1e-10 s (a few rows of a phone's readout), after ten
  // at most (enough for a contraction up to 0.1).
  for (int step = 0; step < 10; ++step) {
    const double t = frame_t + row(s.centre) * row_delay;
    const bool settled = std::abs(t - s.t) < 1e-10;
    s = At(t);
    if (settled) break;
  }
  return s;
}

}  // namespace uphill::internal
