#include "doubtful_rows.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <map>

#include "motion_prediction.hpp"

namespace uphill::internal {

long LeaveOutDoubtfulRows(double min_quality, std::vector<TrackRow>* rows) {
  std::vector<TrackRow>& r = *rows;
  const int n = static_cast<int>(r.size());
  // Each doubted row's distance from the motion around it, px (0 where too few rows are found
  // around it).
  std::map<int, double> off;
  const auto judge = [&](int i) {
    std::vector<TimedCentre> around;
    for (int j = std::max(0, i - kDoubtfulAroundFrames); j <= std::min(n - 1, i + kDoubtfulAroundFrames); ++j)
      if (j != i && r[j].ball.found) around.push_back({r[j].t, Eigen::Vector2d(r[j].ball.u, r[j].ball.v)});
    const auto motion = around.size() >= 3 ? MotionFit::Through(around) : std::nullopt;
    off[i] = motion ? (motion->At(r[i].t).centre - Eigen::Vector2d(r[i].ball.u, r[i].ball.v)).norm() : 0.0;
  };
  for (int i = 0; i < n; ++i)
    if (r[i].ball.found && r[i].ball.quality < min_quality) judge(i);
  long left = 0;
  while (!off.empty()) {
    const auto worst = std::max_element(off.begin(), off.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    if (worst->second <= kDoubtfulOffMotionPx) break;
    const int i = worst->first;
    off.erase(worst);
    r[i].ball = BallObservation{};
    ++left;
    for (auto it = off.lower_bound(i - kDoubtfulAroundFrames); it != off.end() && it->first <= i + kDoubtfulAroundFrames; ++it)
      judge(it->first);
  }
  return left;
}

}  // namespace uphill::internal
