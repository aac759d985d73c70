// Errors in both variables: the maximum-likelihood straight line of York et al. (2004),
// "Unified equations for the slope, intercept, and standard errors of the best straight line",
// Am. J. Phys. 72, 367 - for uncorrelated u(X_i), u(Y_i) (their r_i = 0).
//
// Formulation. With Gaussian errors and the true X's eliminated (profiled out), the likelihood
// is maximised by minimising
//     S(k, c) = Σ (Y_i − c − k·X_i)² / (u(Y_i)² + k²·u(X_i)²),
// York's criterion; his iterative equations are its stationarity conditions. Ceres minimises S
// as a sum of squares of r_i = (Y_i − c − k·X_i)/sqrt(u(Y_i)² + k²u(X_i)²) (a CostFunction with
// the analytic Jacobian below, one block of N residuals: one vectorised O(N) pass per
// evaluation, no N×N matrix). Seed: York's effective-variance iteration (weighted least squares
// at W_i = 1/(u(Y)² + k²u(X)²) of the previous slope, by sums over the standardised rows with
// Eigen arrays) until the slope moves by < 1e-9 relative, so that Ceres needs few steps; after
// Ceres, Gauss-Newton refinement on the same cost function (fit_options.hpp). The result agrees with York's own
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
//
// Cost (`uphill bench fit`, one core, thread CPU time): 10^4 rows ≈ 3 ms, 10^6 rows ≈ 0.48 s.
// Profile at 10^4: ~35 % inside Ceres (three Levenberg-Marquardt iterations with dense QR, and
// ceres::Covariance's dense SVD of the N×2 Jacobian), ~20 % the kernel zeroing fresh pages for
// the N-sized buffers each stage allocates, ~15 % the refinement's long-double sums, ~8 % the
// cost function itself. A vectorised NumPy York iteration (no covariance, no per-row results)
// takes ~0.09 s at 10^6: see README.md, "Benchmarks: fit".
#pragma once

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

FitReport FitErrorsInVariables(const LineData& data, const FitOptions& options = {});

}  // namespace uphill
