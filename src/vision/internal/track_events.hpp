// Internal to src/vision: the event detection of AnalyseTrack (track_analysis.hpp) — where the
// ball leaves a band around its position, turning points as parabola vertices, and the final
// rest with its approach.
#pragma once

#include <optional>
#include <vector>

#include "track_series.hpp"
#include "vision/track_analysis.hpp"

namespace uphill::internal {

// Walking from the first frame (backward: from the last), the number of frames before the first
// one that leaves the band |x − m| ≤ band, m the median of at most `reference` frames before it,
// confirmed by `confirm` consecutive frames out on the same side; nullopt if none leaves.
std::optional<int> FirstDeparture(const std::vector<double>& v, bool backward, double band, int confirm,
                                  int reference);

// The vertex of a least-squares parabola x = c0 + c1·τ + c2·τ², τ = t − t[centre], through the
// frames around `centre` whose smoothed x is within `reach` of the centre's (at least two on
// each side); frames more than 4σ off the first parabola (glitches) are dropped and it is fitted
// again. Time and position with standard errors from the stated σ. nullopt when the parabola
// does not turn the right way (sign = +1 a maximum) or its vertex lies outside the frames used.
std::optional<TrackEvent> ParabolaVertex(const Series& s, const std::vector<double>& smooth, int centre, double reach,
                                         int sign, double sigma, int lo_limit, int hi_limit);

// The final rest from the frames [begin, end): x = x_r for t ≥ t_r and x = x_r + c·(t_r − t)²
// before (the body stops with a finite deceleration, so it creeps into its rest position, and a
// plain mean of the frames near it is biased toward where it came from). Least squares in
// (x_r, c) for each candidate t_r among the frame times, the t_r of the smallest residual sum
// kept; u(x_r) from the residual scatter and the design at that t_r.
struct RestFit {
  Estimate x;
  double t = 0, scatter = 0;
  int frames = 0;
};
std::optional<RestFit> FitRest(const Series& s, int begin, int end, int min_frames);

}  // namespace uphill::internal
