// Reference solutions of the straight-line fits Y = k·X + c, in extended precision, written
// without the fit layer's code (no centring by the library's rules, no Ceres): the truth that
// tests/fit_oracle_test.cpp and `uphill bench fit` compare the fits with.
//
// Inputs are the doubles as given, treated as exact. Outputs are rounded once to double.
//
//   OrdinaryLeastSquares   closed form with centred sums in boost::multiprecision::
//                          cpp_bin_float_50 (50 decimal digits): exact to the last bit of
//                          the double result for any data binary64 can hold.
//   WeightedLeastSquares   the same with w_i = 1/u(Y_i)².
//   YorkLine               York, Evensen, Martínez López & De Basabe Delgado (2004), section III
//                          with r_i = 0: the slope iteration and their eq. 13 errors, in long
//                          double (64-bit significand) on X centred at its middle row's value, to
//                          the rounding floor of long double (the iteration converges linearly).
//   HuberLine              Huber's M-estimate with σ_i = u(Y_i): minimises Σ ρ((r_i/σ_i)²),
//                          ρ(q) = q for |r/σ| ≤ δ, 2δ|r/σ| − δ² beyond, by Newton steps on the
//                          current inlier set (exact for a fixed set) with step halving, in long
//                          double, from the WLS line.
//   HuberLineMadScale      the same with one common σ estimated with the line: σ = 1.4826·MAD,
//                          MAD = median |r_i| of the robust residuals, iterated with the line to
//                          a joint fixed point (the convention of FitRobust without u(Y) and of
//                          statsmodels' RLM with its default scale_est = "mad").
//
// Covariance (unscaled; the stated σ propagated, OLS: σ = 1 in Y's units):
//   least squares  (Σ w_i x_i x_iᵀ)⁻¹, x_i = (X_i, 1);
//   York           eq. 13: σ_k² = 1/Σ W_i (ξ_i − ξ̄)², σ_c² = 1/Σ W_i + ξ̄²σ_k², cov = −ξ̄σ_k²;
//   Huber          the IRLS one at the final weights, (Σ w_i x_i x_iᵀ/σ_i²)⁻¹, w_i = min(1, δ/|r_i/σ_i|)
//                  (for the MAD variant σ_i = σ).
// chi2 is the method's Σ (r_i/σ_i)² (OLS: the residual sum of squares; York: Σ W_i r_i²; Huber:
// Σ w_i (r_i/σ_i)²); dof = N − 2. The scaled ("external") errors are the unscaled ones × chi2/dof.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace uphill::oracle {

// The columns of a line fit; built from anything with members x, y, u_x, u_y (a LineData).
struct LineRows {
  std::span<const double> x, y, u_x, u_y;
  template <typename Data>
  LineRows(const Data& d) : x(d.x), y(d.y), u_x(d.u_x), u_y(d.u_y) {}  // NOLINT: implicit on purpose
  LineRows(std::span<const double> x_, std::span<const double> y_, std::span<const double> ux,
           std::span<const double> uy)
      : x(x_), y(y_), u_x(ux), u_y(uy) {}
  std::size_t size() const { return x.size(); }
};

struct LineSolution {
  double k = 0, c = 0;                  // slope, intercept
  double var_k = 0, var_c = 0, cov_kc = 0;  // unscaled covariance of (k, c)
  double chi2 = 0;
  int dof = 0;
  double sigma = 1;  // HuberLineMadScale: the common scale σ (Y's units); 1 otherwise

  double ScaledVarK() const { return var_k * chi2 / dof; }
  double ScaledVarC() const { return var_c * chi2 / dof; }
  // (k, c, σ_k, σ_c) with the scaled (OLS's convention) or the unscaled standard errors.
  std::vector<double> Values(bool scaled) const;
};

LineSolution OrdinaryLeastSquares(LineRows d);
LineSolution WeightedLeastSquares(LineRows d);
LineSolution YorkLine(LineRows d);
LineSolution HuberLine(LineRows d, double delta = 1.345);
LineSolution HuberLineMadScale(LineRows d, double delta = 1.345);

}  // namespace uphill::oracle
