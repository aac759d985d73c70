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
// rounds of fits and refines it by a third, each round's mean taken over the frames that fitted
// in every round so far; the third round's standard error, divided by 1 − s as the fixed point
// divides the mean's error (q* = c/(1 − s)), is its standard uncertainty.
//
// Accuracy: exact for est(q) linear in q with s in [0, 0.8] and the fixed point inside [0, most]
// (tests/vision_rolling_shutter_test.cpp); on the ray-traced phone clip (readout 25 ms, 15
// frames) it gives 28.2 ± 2.2 ms with tracker version 12, with the renderer's camera as with the
// user's calibration, where the median of the frames' estimates, the first five probed from a
// global shutter, gave 13.7 and 14.4 ms with no uncertainty (docs/track.md).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

namespace uphill::internal {

// One frame's fit at a delay: the delay its rays prefer and that estimate's standard error (> 0),
// s per row; nullopt where the fit failed or did not see the shear.
struct FrameDelay {
  double estimate = 0, sigma = 0;
};
using FrameFit = std::optional<FrameDelay>;

// The frames fitted at row delay q: their mean preferred delay and its standard error, s per row.
struct DelayRound {
  double q = 0, mean = 0, se = 0;
};

// The inverse-variance mean of the frames' preferred delays fitted at q, over the frames `use`
// marks, and its standard error: the larger of the formal one, 1/sqrt(Σw), and the one their
// scatter shows (the fits disagree by more than their curvature says where the body's model errs:
// its shading, the smear's ends). nullopt for fewer than max(min_frames, 2) frames.
std::optional<DelayRound> PreferredDelay(double q, const std::vector<FrameFit>& fits, const std::vector<bool>& use,
                                         std::size_t min_frames);

struct SettledDelay {
  double delay = 0, u = 0;  // s per row
  double slope = 0;         // s of est(q) ≈ c + s·q, kept in [0, 0.8]
  int frames = 0;           // that fitted in every round
};

// From the clip's running estimate `start`, with `fit_frames(q)` every kept frame's fit at q (the
// same frames, in the same order, each round), the delay kept in [0, most]. nullopt when fewer
// than `min_frames` fit in every round.
std::optional<SettledDelay> SettleRowDelay(double start, double most, std::size_t min_frames,
                                           const std::function<std::vector<FrameFit>(double)>& fit_frames);

}  // namespace uphill::internal
