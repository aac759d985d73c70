// Internal to src/vision: a rolling shutter's row delay for a whole clip, from the frames that
// measured it (ball_tracker.hpp, "Time"; the tracker's SettleReadout).
//
// Each such frame's outline fit, made at the clip's running delay q, gives the delay its rays
// prefer with every parameter free (outline_fit.hpp, FitOutcome::row_delay): one Gauss–Newton
// step from q, so exact to first order in the distance to that frame's least-squares delay and
// off by its square beyond (on the brute-force picture of tests/vision_rolling_shutter_test.cpp,
// 24.4 ms from a global shutter for a 25 ms readout, 25.2 ms from 25 ms). The frames share the
// delay and nothing else, so the clip's least-squares delay is their estimates' inverse-variance
// mean. SettleRowDelay takes it, fits again at that mean the frames whose fits were made farther
// from it than `near` (the first frames of a clip are fitted at a global shutter's 0), and takes
// the mean again: one round of refits of the far frames only.
//
// Accuracy: on ray-traced rolling-shutter footage (readout 25 ms, 15 frames) within about one
// standard error (≈ 2 ms) of the true readout, with the renderer's camera and with a calibrated
// one; the standard error is from the frames' scatter where it exceeds their formal
// errors (tests/vision_rolling_shutter_test.cpp). It does not hold the smear model's errors,
// which shift every frame alike: the tracker adds a systematic term (ball_tracker.cpp).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

namespace uphill::internal {

// One frame's estimate of the row delay and its standard error (> 0), s per row; nullopt where
// the fit failed or did not see the shear.
struct FrameDelay {
  double estimate = 0, sigma = 0;
};
using FrameFit = std::optional<FrameDelay>;

// The frames' mean preferred delay and its standard error, s per row.
struct DelayMean {
  double mean = 0, se = 0;
};

// The inverse-variance mean of the frames' estimates, and its standard error: the larger of the
// formal one, 1/sqrt(Σw), and the one their scatter shows (the fits disagree by more than their
// curvature says where the body's model errs: its shading, the smear's ends). nullopt for fewer
// than max(min_frames, 2) frames.
std::optional<DelayMean> PreferredDelay(const std::vector<FrameFit>& fits, std::size_t min_frames);

struct SettledDelay {
  double delay = 0, u = 0;  // s per row
  int frames = 0;           // that the mean is over
  int refitted = 0;         // of them, fitted again at the first mean
};

// The clip's row delay from its frames' estimates `fits`, frame i's made by a fit at delay
// fitted_at[i]: their mean, the frames fitted farther than `near` from it replaced by
// refit(i, mean), and the mean again; kept in [0, most]. nullopt when fewer than `min_frames`
// frames have an estimate at either step.
std::optional<SettledDelay> SettleRowDelay(std::vector<FrameFit> fits, const std::vector<double>& fitted_at,
                                           double near, double most, std::size_t min_frames,
                                           const std::function<FrameFit(std::size_t, double)>& refit);

}  // namespace uphill::internal
