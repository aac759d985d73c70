// Errors in both variables: the maximum-likelihood straight line of York et al. (2004),
// "Unified equations for the slope, intercept, and standard errors of the best straight line",
// Am. J. Phys. 72, 367 - for uncorrelated u(X_i), u(Y_i) (their r_i = 0).
//
// Formulation. With Gaussian errors and the true X's eliminated (profiled out), the likelihood
// is maximised by minimising
//     S(k, c) = Σ (Y_i − c − k·X_i)² / (u(Y_i)² + k²·u(X_i)²),
// York's criterion; his iterative equations are its stationarity conditions. Ceres minimises S
// as a sum of squares of r_i = (Y_i − c − k·X_i)/sqrt(u(Y_i)² + k²u(X_i)²) (AutoDiffCostFunction,
// one block of N residuals: O(N) per iteration, no N×N matrix). Seed: weighted least squares
// followed by two effective-variance iterations (closed forms, O(N)); after Ceres, Gauss-Newton
// refinement on the same cost function (fit_options.hpp). The result agrees with York's own
// iteration, carried out in long double, to 1e-13 (line) and 1e-12 (covariance) (tests).
//
// Standard errors. The Jacobian of r_i is −sqrt(W_i)·(ξ_i, 1), W_i = 1/(u(Y)² + k²u(X)²) and
// ξ_i = X_i + k·u(X_i)²·W_i·(Y_i − c − k·X_i) the adjusted (least-squares estimate of the true)
// X_i, so the Gauss-Newton covariance (JᵀJ)⁻¹ that ceres::Covariance returns is exactly York's
//     σ_k² = 1/Σ W_i (ξ_i − ξ̄)²,   σ_c² = 1/Σ W_i + ξ̄²σ_k²,   ξ̄ = Σ W_i ξ_i / Σ W_i
// (York 2004 eq. 13; the same as the Fisher information with the true X's as parameters).
// Both conventions are reported, as the literature does: unscaled (York's; primary) and scaled
// by sqrt(MSWD) = sqrt(S/(N − 2)) (as e.g. scipy.odr's sd_beta and Isoplot's "external" errors).
//
// Per row: residual Y_i − c − k·X_i, σ_i = sqrt(u(Y_i)² + k²u(X_i)²), chi2 = S.
// Test: Pearson's (1901) data with York's (1966) weights gives k = −0.480533407,
// c = 5.479910224, σ_k = 0.0579850, σ_c = 0.2949707 (unscaled), MSWD = 1.483294.
//
// Requirements: u(Y_i) finite and > 0 (so every W_i is finite whatever the slope), u(X_i) finite
// and ≥ 0 (0: that X is exact). All u(X) = 0 reduces to WLS. Otherwise as least_squares_line.hpp.
#pragma once

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

FitReport FitErrorsInVariables(const LineData& data, const FitOptions& options = {});

}  // namespace uphill
