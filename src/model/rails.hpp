// Rails: the two straight rail lines r±(t) = (t, ±t·tan(α/2), t·tanθ), t ≥ 0, that meet at O.
//
// Frame (docs/physics.md "Frame and apparatus"): O is the meeting point, x horizontal along the centre line toward the rising,
// diverging end, y horizontal across, z up. θ is the inclination, α the divergence angle in the
// horizontal projection, φ the 3-D half angle between the rails: tanφ = tan(α/2)·cosθ.
//
// The lab measures L, H, D at the crossbar (all in metres here):
//   kHorizontal (default): L horizontal distance O→crossbar; tanθ = H/L, tan(α/2) = D/(2L).
//   kAlongRail:            L measured along a rail; horizontal distance sqrt(L² − H² − D²/4).
// Slopes are kept exactly as measured (H/L, D/2L) rather than round-tripped through atan/tan,
// so the model sees the measured ratios to within one rounding.
#pragma once

#include <cmath>

#include "model/input_error.hpp"

namespace uphill {

enum class LConvention { kHorizontal, kAlongRail };

// Horizontal distance from O to the crossbar. For kAlongRail the radicand is factored as
// (L − s)(L + s), s = hypot(H, D/2), which keeps full relative accuracy when L is close to s.
// Templated so that ceres::Jet can carry derivatives through it.
template <typename T>
T HorizontalDistance(const T& L, const T& H, const T& D, LConvention convention) {
  using std::hypot;
  using std::sqrt;
  if (convention == LConvention::kHorizontal) return L;
  const T s = hypot(H, D / 2.0);
  return sqrt((L - s) * (L + s));
}

struct Rails {
  double theta = 0.0;           // inclination, rad, in [0, π/2)
  double alpha = 0.0;           // divergence angle, rad, in (0, π)
  double tan_theta = 0.0;       // B in docs/physics.md
  double tan_half_alpha = 0.0;  // T in docs/physics.md

  // From angles. Throws InputError unless 0 ≤ θ < π/2 and 0 < α < π.
  static Rails FromAngles(double theta, double alpha);
  // From the crossbar measurements (metres). Throws InputError for non-positive or
  // non-finite values, H ≥ 0 is allowed (θ = 0), and for kAlongRail when L ≤ hypot(H, D/2).
  static Rails FromApparatus(double L, double H, double D, LConvention convention);

  // φ, the 3-D half angle between the rails (rad).
  double HalfAngleBetweenRails() const;
};

}  // namespace uphill
