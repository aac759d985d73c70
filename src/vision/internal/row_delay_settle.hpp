// Internal to src/vision: a rolling shutter's row delay for a whole clip, from the frames that
// measured it (ball_tracker.hpp, "Time"; the tracker's SettleReadout).
//
// A frame's outline fit at a row delay q says which delay its rays prefer, the centre and smear
// held (outline_fit.hpp, FitOutcome::row_delay): est(q). Held, they have absorbed part of the
// shear that q got wrong, so est(q) moves from q toward the truth by a share (1 − s) of the way
// only: est(q) ≈ c + s·q over the frames (s ≈ 0.47 on the ray-traced phone clip of
// docs/track.md, 0 for a body whose fit cannot absorb the shear). The delay where the frames'
// mean est(q) equals q is a stationary point of their χ² with every parameter free: the
// least-squares delay of those frames. SettleRowDelay finds it by a secant step through two
// rounds of fits and refines it by a third; the third round's standard error, divided by
// 1 − s as the fixed point divides the mean's error (q* = c/(1 − s)), is its standard
// uncertainty.
//
// Accuracy: exact for est(q) linear in q (tests/vision_rolling_shutter_test.cpp); on the
// ray-traced phone clip (readout 25 ms, 15 frames) it gives 18.1 ± 2.8 ms, where the median of
// the frames' estimates from q = 0 gave 14.4 ms with no uncertainty (docs/track.md).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

namespace uphill::internal {

// The frames fitted at row delay q: their mean preferred delay and its standard error, s per row.
struct DelayRound {
  double q = 0, mean = 0, se = 0;
};

// The inverse-variance mean of the preferred delays `estimates` (standard errors `sigmas`, all
// > 0) fitted at q, and its standard error: the larger of the formal one, 1/sqrt(Σw), and the one
// their scatter shows (the fits disagree by more than their curvature says where the body's
// model errs: its shading, the smear's ends). nullopt for fewer than `min_frames` (≥ 2).
std::optional<DelayRound> PreferredDelay(double q, const std::vector<double>& estimates,
                                         const std::vector<double>& sigmas, std::size_t min_frames);

struct SettledDelay {
  double delay = 0, u = 0;  // s per row
  double slope = 0;         // s of est(q) ≈ c + s·q, kept in [0, 0.8]
};

// From the clip's running estimate `start`, with `fit_at(q)` the frames' round at q (nullopt when
// too few of them fit), the delay kept in [0, most]. nullopt when a round fails.
std::optional<SettledDelay> SettleRowDelay(double start, double most,
                                           const std::function<std::optional<DelayRound>(double)>& fit_at);

}  // namespace uphill::internal
