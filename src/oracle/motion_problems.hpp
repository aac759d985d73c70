// The three trajectories of `uphill bench motion` (also checked by tests/motion_trajectory_test.cpp),
// each with its 50-digit reference: a solid spheroid a = 20 mm, b = 32 mm (b/a = 1.6, the paper's
// FIG. 4 family) on line rails θ = 1°, α = 30°, g = 9.80665 m/s², x0 = 1.05·X, and
//   kRelease      released at rest, μ = 0: it rolls away from O and falls off; the times at n
//                 positions equally spaced from x0 to 0.99·x_max (x_i = x0 + (0.99·x_max − x0)·i/n);
//   kTurning      thrown toward O at half the speed that would carry it over X, μ = 0: it climbs,
//                 turns, and falls off; the first times at n/2 positions equally spaced from the
//                 turning point (excluded) to 90 % of the way to x0, and n/2 from x0 to 0.99·x_max;
//   kComesToRest  μ = half the slope |dz/dx| at x0, thrown toward O with the speed that stops it
//                 halfway between X and the upper edge of the rest band: it comes to rest; the times
//                 at n positions equally spaced from the rest point (excluded) to 90 % of the way to x0.
// The positions on the way back stop short of x0 because a time t ≈ (x0 − x)/|v0| just after the
// start has condition number ≈ x/(x0 − x): binary64 positions alone would limit it to ~1e-12.
// The initial speeds are set from the model's closed forms (Scene: heights, K); the references
// come from oracle/motion_reference.hpp (release: also release_times_reference.hpp).
#pragma once

#include <string>
#include <vector>

#include "model/scene.hpp"
#include "oracle/motion_reference.hpp"

namespace uphill::oracle {

enum class MotionProblemKind { kRelease, kTurning, kComesToRest };

struct MotionProblem {
  std::string name;  // "release", "turns", "comes to rest"
  double a, b, g;    // m, m, m/s²
  Scene scene;
  double x0, v0, mu;
  std::vector<double> xs;        // positions, m
  TrajectoryReference reference;  // times at xs, events
};

// n ≥ 2 positions (even for kTurning).
MotionProblem MakeMotionProblem(MotionProblemKind kind, int n);

}  // namespace uphill::oracle
