// The ranges of the quantities uphill takes in: one set of rules for every door (the command
// line, the page through io's readers, the Python module), so that a value one of them refuses
// no other accepts. Outside these ranges the model's numbers overflow or lose every digit (inf or
// NaN in the output), or the value means nothing for a ball on a lab's rails.
//
// Contract: each check accepts finite values in its range and otherwise throws InputError whose
// quantity is the name it was given (a flag, a JSON key, an argument) and whose rule names the
// value with its SI unit and the range, e.g. "u_x: must lie between 1 nm and 1000 km (got
// 1e+308 m) ...". NaN and the infinities are refused by every check.
#pragma once

#include <string>

namespace uphill {

// Lengths (m): why 1 nm to 1000 km — the reference tests span micrometres to kilometres, and
// squares and products of such lengths and of their ratios stay far inside binary64.
inline constexpr double kShortestModelLength = 1e-9, kLongestModelLength = 1e6;

// A length of the apparatus, of the sign the model's own rules judge: 0 or ±[1 nm, 1000 km]
// (0: a height of 0, line rails).
void RequireModelLength(const std::string& quantity, double metres);
// A length that must be > 0 (a position's standard uncertainty): [1 nm, 1000 km].
void RequirePositiveLength(const std::string& quantity, double metres);
// A standard uncertainty of a length: 0 (exact) or [1 nm, 1000 km].
void RequireLengthUncertainty(const std::string& quantity, double metres);
// A standard uncertainty of an angle: [0, π] rad — a wider spread covers every direction.
void RequireAngleUncertainty(const std::string& quantity, double radians);

// Gravitational acceleration: [1e-3, 1e3] m/s² — times scale as 1/sqrt(g); far outside, the end
// time of the motion overflows or its integrator's steps lose every digit.
inline constexpr double kSmallestGravity = 1e-3, kLargestGravity = 1e3;
void RequireGravity(const std::string& quantity, double metres_per_second2);

// Initial speed of the centre: |v0| ≤ 1000 m/s — far beyond a throw by hand the integrator's
// steps shrink below the resolution of the time.
inline constexpr double kFastestSpeed = 1e3;
void RequireSpeed(const std::string& quantity, double metres_per_second);

// Rolling resistance (a slope threshold): [0, 10] — 10 is a slope of 84°, steeper than any rail
// the model describes; the rest band's root solve needs a finite slope.
inline constexpr double kLargestRollingResistance = 10.0;
void RequireRollingResistance(const std::string& quantity, double mu);

// Monte Carlo trials: [100, 10^8] — fewer give a standard deviation not worth quoting, more only
// waste time (its relative statistical error is already 0.007 % at 10^8).
inline constexpr double kFewestTrials = 100, kMostTrials = 1e8;
// `trials` as given (a double holds any integer a caller may pass, negative or huge).
void RequireMonteCarloTrials(const std::string& quantity, double trials);

class Scene;

// A scene whose positions lie in the lengths' range: X and x_max (x_fall for the double cone)
// finite and at most 1000 km from O, x_low finite, θ and α finite. Lengths in range can still
// give a divergence angle of a few ulp, which puts X at 1e300 m, where the motion's integrator
// never finishes. Throws InputError("the setting", …) naming the position.
void RequireSceneInRange(const Scene& scene);

// The last guard before a result leaves the library: the ranges above keep the known cases
// finite, and a combination they miss (an extreme ratio of two lengths, a divergence angle of a
// few ulp) is refused rather than shown as inf or NaN. Throws InputError("the setting", …)
// naming `what` when `value` is not finite.
void RequireFiniteResult(const std::string& what, double value);

}  // namespace uphill
