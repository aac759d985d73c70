// Reference for the rolling-resistance fit (fit/friction_fit.hpp): the Gauss-Newton normal
// equations of Σ (Y_i − s·x_rest,i(μ))²/u(Y_i)² for a spheroid (or sphere, a = b) on line rails,
// in long double, with x_rest and its derivative from the closed form (docs/physics.md
// "Rolling resistance"):
//     x_rest(μ) = x_max·K/sqrt(P·A² + K²),   K = tanθ + μ(1 + A²),
//     dx_rest/dμ = x_max·P·A²(1 + A²)/(P·A² + K²)^(3/2),
// evaluated by the model's SpheroidOnLineRails<long double> (the model's closed form, not the
// fit's code path: the fit differentiates it with ceres::Jet through Ceres).
// Used by tests/fit_friction_test.cpp (covariance and stationarity at the fitted μ, s) and by
// `uphill bench fit` (the fitted μ and σ_μ).
#pragma once

#include <span>

namespace uphill::oracle {

// Rows of the same body: a, b (m) and per row the rails' tanθ and tan(α/2), Y and u(Y) (m).
struct FrictionRows {
  double a = 0, b = 0;
  std::span<const double> tan_theta, tan_half_alpha, y, u_y;
};

// At (μ, s): the gradient g = Σ J_iᵀ r_i/u_i² and Gauss-Newton matrix H = Σ J_iᵀ J_i/u_i² with
// J_i = (s·dx_rest/dμ, x_rest), r_i = Y_i − s·x_rest(μ); scale_* = Σ |J_i,· Y_i|/u_i², the size
// of the terms whose sum g is (for a stationarity test g ≈ 0 relative to it).
struct FrictionNormalEquations {
  long double g_mu = 0, g_s = 0;
  long double h_mu_mu = 0, h_mu_s = 0, h_s_s = 0;
  long double scale_mu = 0, scale_s = 0;
};
FrictionNormalEquations FrictionAt(const FrictionRows& rows, long double mu, long double s = 1);

// μ by Gauss-Newton with s = 1 fixed, from `mu_start`, to the rounding floor of long double;
// var_mu = 1/H_μμ at the solution (the unscaled variance).
struct FrictionSolution {
  double mu = 0, var_mu = 0;
};
FrictionSolution FrictionMu(const FrictionRows& rows, double mu_start);

}  // namespace uphill::oracle
