// The tracker's assess stage (tracker_state.hpp): the last look at a frame's position before it
// is reported. The tracker's own state (its history, its prediction) keeps what it measured;
// only the report leaves out what the path contradicts.
#include <algorithm>
#include <cmath>
#include <iterator>

#include "tracker_state.hpp"

namespace uphill {

double BallTracker::Impl::AcrossPathPx(double x, double z) const {
  return (z - scene.At(std::clamp(x, x_lo, x_hi)).z) / MetresPerPx(x, z);
}

bool BallTracker::Impl::OnPathAcross(double x, double z) const { return HeightOnPath(AcrossPathPx(x, z)); }

double BallTracker::Impl::UsualHeight() const {
  std::vector<double> sorted(across_path.begin(), across_path.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

bool BallTracker::Impl::HeightOnPath(double height) const {
  if (std::abs(height) <= kOnPathPx) return true;
  if (across_path.size() < kOnPathMinFrames) return std::abs(height) <= kOnPathFirstPx;
  return std::abs(height - UsualHeight()) <= kOnPathUsualPx;
}

BallObservation BallTracker::Impl::Assess(const cv::Mat& frame, const BallObservation& o) {
  if (!o.found) return o;
  auto reported = [&](const BallObservation& r) {
    const double height = AcrossPathPx(r.x, r.z);
    if (std::abs(height) <= kOnPathPx) on_path_x = r.x;
    if (adopted_left > 0) --adopted_left, provisional.push_back({frame_index, height, true});
    else if (across_path.size() < kOnPathMinFrames && std::abs(height) > kOnPathPx)
      provisional.push_back({frame_index, height, false});
    across_path.push_back(height);
    if (across_path.size() > kOnPathFrames) across_path.pop_front();
    return r;
  };
  const double height = AcrossPathPx(o.x, o.z);
  if (OnPathAcross(o.x, o.z)) {
    left_heights.clear();
    return reported(o);
  }
  // The contrast at the outline alone, searched as wide as the search for a body found anew (a
  // print's edge holds the model's outline a few pixels off the body), with its own polarity,
  // and taken where it finds the outline as the search would find a body anew: a faint one
  // counts where its edges lie on it sharply (a striped ball on a cloth of its grey, whose
  // stripes held the model's outline 6 px off it, was otherwise left out in 29 of its 30 frames).
  internal::EdgeFit outline = *edges;
  outline.Reset();
  const internal::EdgeFitOutcome e = outline.Measure(frame, o.x, o.z, 2 * options.search_half_width_px);
  if ((OutlineFound(e) || FaintOutlineFound(e)) && OnPath(e.x, e.z) && OnPathAcross(e.x, e.z)) {
    BallObservation by_edges = ObserveEdges(e);
    by_edges.time_offset = o.time_offset;
    left_heights.clear();
    return reported(by_edges);
  }
  // A calibration that puts the path farther off than kOnPathFirstPx: the frames left out in a
  // row lie at one height off it. From kOnPathAdoptFrames of them on, that height is the path's.
  left_heights.push_back(height);
  const auto [low, high] = std::minmax_element(left_heights.begin(), left_heights.end());
  const bool seen_on_path_here = on_path_x && std::abs(o.x - *on_path_x) < scene.body().across;
  if (left_heights.size() >= kOnPathAdoptFrames && *high - *low <= kOnPathUsualPx && !seen_on_path_here) {
    across_path.assign(left_heights.begin(), std::prev(left_heights.end()));  // reported(o) adds this frame's
    left_heights.clear();
    adopted_left = kOnPathFrames;
    return reported(o);
  }
  if (left_heights.size() >= kOnPathAdoptFrames) left_heights.pop_front();
  ++left_off_path;
  return {};
}

void BallTracker::Impl::RejudgeProvisionalFrames() {
  if (across_path.size() < kOnPathMinFrames) return;
  const bool adoption_disproved = std::abs(UsualHeight()) <= kOnPathPx;
  for (const Provisional& p : provisional) {
    if (p.adopted && !adoption_disproved) continue;
    const long k = p.frame;
    const auto last = std::find_if(revisions.rbegin(), revisions.rend(), [k](const auto& r) { return r.first == k; });
    if (last != revisions.rend() && (!last->second.found || OnPathAcross(last->second.x, last->second.z))) continue;
    if (last == revisions.rend() && HeightOnPath(p.height)) continue;
    revisions.emplace_back(k, BallObservation{});
    samples.erase(k);
    ++left_off_path;
  }
  provisional.clear();
}

void BallTracker::Impl::AssessRevisions(std::vector<std::pair<long, BallObservation>>* revised) {
  std::erase_if(*revised, [this](const auto& r) { return r.second.found && !OnPathAcross(r.second.x, r.second.z); });
  for (const auto& [k, o] : *revised) {
    const auto p = std::find_if(provisional.begin(), provisional.end(), [k](const Provisional& q) { return q.frame == k; });
    if (p == provisional.end()) continue;
    if (o.found) p->height = AcrossPathPx(o.x, o.z);
    else provisional.erase(p);
  }
}

}  // namespace uphill
