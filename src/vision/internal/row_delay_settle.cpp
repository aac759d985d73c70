#include "row_delay_settle.hpp"

#include <algorithm>
#include <cmath>

namespace uphill::internal {

std::optional<DelayRound> PreferredDelay(double q, const std::vector<double>& estimates,
                                         const std::vector<double>& sigmas, std::size_t min_frames) {
  const std::size_t n = estimates.size();
  if (n < std::max<std::size_t>(min_frames, 2) || sigmas.size() != n) return std::nullopt;
  double sw = 0, swe = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 1 / (sigmas[i] * sigmas[i]);
    sw += w;
    swe += w * estimates[i];
  }
  const double mean = swe / sw;
  double scatter = 0;
  for (std::size_t i = 0; i < n; ++i) scatter += (estimates[i] - mean) * (estimates[i] - mean) / (sigmas[i] * sigmas[i]);
  const double se = std::max(std::sqrt(1 / sw), std::sqrt(scatter / (static_cast<double>(n - 1) * sw)));
  return DelayRound{q, mean, se};
}

std::optional<SettledDelay> SettleRowDelay(double start, double most,
                                           const std::function<std::optional<DelayRound>(double)>& fit_at) {
  const std::optional<DelayRound> a = fit_at(std::clamp(start, 0.0, most));
  if (!a) return std::nullopt;
  // The second round where the first points (or a fifth of the range on, when it barely moved:
  // the slope needs two delays apart).
  const double step = std::abs(a->mean - a->q) > 0.1 * most ? a->mean - a->q : (a->q < 0.5 * most ? 0.2 : -0.2) * most;
  const std::optional<DelayRound> b = fit_at(std::clamp(a->q + step, 0.0, most));
  if (!b || b->q == a->q) return std::nullopt;
  SettledDelay out;
  out.slope = std::clamp((b->mean - a->mean) / (b->q - a->q), 0.0, 0.8);
  const double shrink = 1 - out.slope;
  const std::optional<DelayRound> c = fit_at(std::clamp(b->q + (b->mean - b->q) / shrink, 0.0, most));
  if (!c) return std::nullopt;
  out.delay = std::clamp(c->q + (c->mean - c->q) / shrink, 0.0, most);
  out.u = c->se / shrink;
  return out;
}

}  // namespace uphill::internal
