#include "row_delay_settle.hpp"

#include <algorithm>
#include <cmath>

namespace uphill::internal {

std::optional<DelayMean> PreferredDelay(const std::vector<FrameFit>& fits, std::size_t min_frames) {
  double sw = 0, swe = 0;
  std::size_t n = 0;
  for (const FrameFit& f : fits)
    if (f) {
      const double w = 1 / (f->sigma * f->sigma);
      sw += w;
      swe += w * f->estimate;
      ++n;
    }
  if (n < std::max<std::size_t>(min_frames, 2)) return std::nullopt;
  const double mean = swe / sw;
  double scatter = 0;
  for (const FrameFit& f : fits)
    if (f) {
      const double r = (f->estimate - mean) / f->sigma;
      scatter += r * r;
    }
  const double se = std::max(std::sqrt(1 / sw), std::sqrt(scatter / (static_cast<double>(n - 1) * sw)));
  return DelayMean{mean, se};
}

std::optional<SettledDelay> SettleRowDelay(std::vector<FrameFit> fits, const std::vector<double>& fitted_at,
                                           double near, double most, std::size_t min_frames,
                                           const std::function<FrameFit(std::size_t, double)>& refit) {
  const std::optional<DelayMean> first = PreferredDelay(fits, min_frames);
  if (!first) return std::nullopt;
  const double q = std::clamp(first->mean, 0.0, most);
  SettledDelay out;
  for (std::size_t i = 0; i < fits.size() && i < fitted_at.size(); ++i)
    if (fits[i] && std::abs(fitted_at[i] - q) > near && (fits[i] = refit(i, q))) ++out.refitted;
  const std::optional<DelayMean> settled = PreferredDelay(fits, min_frames);
  if (!settled) return std::nullopt;
  out.delay = std::clamp(settled->mean, 0.0, most);
  out.u = settled->se;
  out.frames = static_cast<int>(std::count_if(fits.begin(), fits.end(), [](const FrameFit& f) { return f.has_value(); }));
  return out;
}

}  // namespace uphill::internal
