// Reference release times of a solid spheroid (or sphere, a = b) on line rails, in 50 digits:
// released at rest at x0 beyond X, the times t_i at which its centre reaches the positions x_i
// (increasing, x0 < x_i < x_max).
//
// The energy equation's quadrature in the ellipse form (docs/physics.md): with the ellipse
// parameter ψ (x = x_max·sinψ), u = ψ − ψ0 and the release substitution u = u0·cosh w, the
// integrand dt/dw = sqrt(K·M/(g·z_eq·sinc(u0·ch²)·sinc(u0·sh²))) (ch = cosh(w/2), sh = sinh(w/2);
// M = x_max²cos²ψ + z_eq²sin²u; K = 1 + (2/5)/(cos²(ψ+γ) + (A²/P)sin²(ψ+γ)), the solid spheroid's
// rolling inertia) is smooth, and each interval [w_{i−1}, w_i] is integrated by Gauss–Kronrod 61
// in boost::multiprecision::cpp_bin_float_50 to 1e-35. Independent of src/motion (which integrates
// in another variable, in binary64); its error is far below 1e-20 relative.
// Used by `uphill bench motion` (the times' error of every method).
#pragma once

#include <span>
#include <vector>

namespace uphill::oracle {

std::vector<double> SpheroidReleaseTimes(double a, double b, double tan_theta, double tan_half_alpha,
                                         double g, double x0, std::span<const double> xs);

}  // namespace uphill::oracle
