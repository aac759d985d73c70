#include "row_delay_settle.hpp"

#include <algorithm>
#include <cmath>

namespace uphill::internal {

std::optional<DelayRound> PreferredDelay(double q, const std::vector<FrameFit>& fits, const std::vector<bool>& use,
                                         std::size_t min_frames) {
  double sw = 0, swe = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (use[i] && fits[i]) {
      const double w = 1 / (fits[i]->sigma * fits[i]->sigma);
      sw += w;
      swe += w * fits[i]->estimate;
      ++n;
    }
  if (n < std::max<std::size_t>(min_frames, 2)) return std::nullopt;
  const double mean = swe / sw;
  double scatter = 0;
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (use[i] && fits[i]) {
      const double r = (fits[i]->estimate - mean) / fits[i]->sigma;
      scatter += r * r;
    }
  const double se = std::max(std::sqrt(1 / sw), std::sqrt(scatter / (static_cast<double>(n - 1) * sw)));
  return DelayRound{q, mean, se};
}

std::optional<SettledDelay> SettleRowDelay(double start, double most, std::size_t min_frames,
                                           const std::function<std::vector<FrameFit>(double)>& fit_frames) {
  std::vector<bool> use;
  // A round at q: the frames' fits; a frame that failed is dropped from every round's mean (the
  // secant's two means and the last must be over the same frames).
  std::vector<std::vector<FrameFit>> rounds;
  std::vector<double> qs;
  auto round = [&](double q) {
    rounds.push_back(fit_frames(q));
    qs.push_back(q);
    if (use.empty()) use.assign(rounds.back().size(), true);
    for (std::size_t i = 0; i < use.size(); ++i) use[i] = use[i] && i < rounds.back().size() && rounds.back()[i];
  };
  auto mean_of = [&](std::size_t k) { return PreferredDelay(qs[k], rounds[k], use, min_frames); };

  round(std::clamp(start, 0.0, most));
  const std::optional<DelayRound> first = mean_of(0);
  if (!first) return std::nullopt;
  // The second round where the first points, or a fifth of the range on where that barely moves
  // (the slope needs two delays apart), inward from the end the first round stands at.
  double next = std::clamp(first->mean, 0.0, most);
  if (std::abs(next - first->q) < 0.1 * most) next = first->q + (first->q < 0.5 * most ? 0.2 : -0.2) * most;
  round(next);
  const std::optional<DelayRound> a = mean_of(0), b = mean_of(1);
  if (!a || !b || b->q == a->q) return std::nullopt;
  SettledDelay out;
  out.slope = std::clamp((b->mean - a->mean) / (b->q - a->q), 0.0, 0.8);
  const double shrink = 1 - out.slope;
  round(std::clamp(b->q + (b->mean - b->q) / shrink, 0.0, most));
  const std::optional<DelayRound> c = mean_of(2);
  if (!c) return std::nullopt;
  out.delay = std::clamp(c->q + (c->mean - c->q) / shrink, 0.0, most);
  out.u = c->se / shrink;
  out.frames = static_cast<int>(std::count(use.begin(), use.end(), true));
  return out;
}

}  // namespace uphill::internal
