// Closed forms of a spheroid on round rods (docs/physics.md "Round rods"): the fall-off x_max(r) and
// the unstable equilibrium x_eq(r). Only z(x) needs SpheroidOnRods' numeric contact solve; these
// two are explicit, and live here, templated on the scalar, so that ceres::Jet carries first-order
// uncertainty propagation through exactly the expressions SpheroidOnRods evaluates.
//
//   x_max(r) = sqrt(a² + b²·cot²(α/2)) + r/sin(α/2)       (1/sin = hypot(1, T)/T)
//   x_eq(r)  = b²·B/(T·sqrt(b²B² + a²T²)) + r·B/(T·sqrt(B² + T²))
//
// a, b: semi-axes (a in x and z, b along y), m, > 0; B = tanθ ≥ 0; T = tan(α/2) > 0; r ≥ 0, m.
// r = 0 gives the line-rail values (the same numbers as SpheroidOnLineRails to a few ulp; that
// class keeps its own, differently rounded, forms). Accuracy: a few ulp (sums of positive terms).
#pragma once

#include <cmath>

namespace uphill {

template <typename S>
S SpheroidOnRodsXMax(const S& a, const S& b, const S& tan_half_alpha, const S& rod_radius) {
  using std::hypot;
  return hypot(a, b / tan_half_alpha) + rod_radius * hypot(S(1.0), tan_half_alpha) / tan_half_alpha;
}

template <typename S>
S SpheroidOnRodsXEq(const S& a, const S& b, const S& tan_theta, const S& tan_half_alpha,
                    const S& rod_radius) {
  using std::hypot;
  return b * b * tan_theta / (tan_half_alpha * hypot(b * tan_theta, a * tan_half_alpha)) +
         rod_radius * tan_theta / (tan_half_alpha * hypot(tan_theta, tan_half_alpha));
}

}  // namespace uphill
