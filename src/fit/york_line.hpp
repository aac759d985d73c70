// Errors in both variables: the maximum-likelihood straight line of York et al. (2004),
// "Unified equations for the slope, intercept, and standard errors of the best straight line",
// Am. J. Phys. 72, 367 - for uncorrelated u(X_i), u(Y_i) (their r_i = 0).
//
// Formulation. With Gaussian errors and the true X's eliminated (profiled out), the likelihood
// is maximised by minimising
//     S(k, c) = Σ (Y_i − c − k·X_i)² / (u(Y_i)² + k²·u(X_i)²),
// York's criterion; his iterative equations are its stationarity conditions. Ceres minimises S
// as a sum of squares of r_i = (Y_i − c − k·X_i)/sqrt(u(Y_i)² + k²u(X_i)²) with the analytic
// Jacobian below, handed over compressed: every quantity Ceres' Levenberg-Marquardt iteration
// and ceres::Covariance use (cost, Jᵀr, JᵀJ) is a sum over the rows, computed in one vectorised
// pass per evaluation and passed to Ceres as 3 residuals with the same cost, gradient and
// Gauss-Newton matrix (internal/compressed_cost.hpp): Ceres iterates exactly as on the N-row
// problem, without N×2 storage. Seed: the WLS line in u(Y) (York's criterion at k = 0), from
// which Ceres converges in 3-4 steps (Gauss-Newton gains ~1e-2-1e-3 per step here; its cost test
// stops it with parameters good to ~1e-9); then Newton's method on S with the exact Hessian
// (one step to the rounding level), checked in the pass that writes the per-row results: if
// the gradient there is not at the rounding level the polish continues. The result agrees
// with York's own iteration, carried out in long double, to 1e-13 (line) and 1e-12
// (covariance), and with ceres::Covariance of the N-residual problem to 1e-12 (tests).
//
// Standard errors. The Jacobian of r_i is −sqrt(W_i)·(ξ_i, 1), W_i = 1/(u(Y)² + k²u(X)²) and
// ξ_i = X_i + k·u(X_i)²·W_i·(Y_i − c − k·X_i) the adjusted (least-squares estimate of the true)
// X_i, so the Gauss-Newton covariance (JᵀJ)⁻¹ that ceres::Covariance returns is exactly York's
//     σ_k² = 1/Σ W_i (ξ_i − ξ̄)²,   σ_c² = 1/Σ W_i + ξ̄²σ_k²,   ξ̄ = Σ W_i ξ_i / Σ W_i
// (York 2004 eq. 13; the same as the Fisher information with the true X's as parameters).
// It is ceres::Covariance's, for every N: computed on the compressed problem, whose 3×2 Jacobian
// has the singular values of the N×2 one, so the rank test and (JᵀJ)⁻¹ are the full problem's
// (a test compares with ceres::Covariance of all N residuals: ≤ 1e-12). On the full problem
// ceres::Covariance would factor an N×2 Jacobian, several times the cost of the whole fit.
// Both conventions are reported, as the literature does: unscaled (York's; primary) and scaled
// by sqrt(MSWD) = sqrt(S/(N − 2)) (as e.g. scipy.odr's sd_beta and Isoplot's "external" errors).
//
// Per row: residual Y_i − c − k·X_i, σ_i = sqrt(u(Y_i)² + k²u(X_i)²), chi2 = S; stored in
// FitReport::rows with FitOptions::keep_rows, else computed in the last pass and given on demand
// by LineRowResults (line_rows.hpp).
// Test: Pearson's (1901) data with York's (1966) weights gives k = −0.480533407,
// c = 5.479910224, σ_k = 0.0579850, σ_c = 0.2949707 (unscaled), MSWD = 1.483294.
//
// Requirements: u(Y_i) finite and > 0 (so every W_i is finite whatever the slope), u(X_i) finite
// and ≥ 0 (0: that X is exact). All u(X) = 0 reduces to WLS. Otherwise as least_squares_line.hpp.
//
// Cost: O(N) per pass over the rows, about 8 passes (validation, centring, seed, Ceres, Newton,
// per-row results; the row kernel is vectorised with `omp simd` and, where the CPU has it, an
// AVX2 clone), plus writing the per-row results. No N-sized buffer besides the result. Measured
// against NumPy's York iteration and scipy.odr by `uphill bench fit` (docs/benchmarks.md).
#pragma once

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

FitReport FitErrorsInVariables(const LineData& data, const FitOptions& options = {});

}  // namespace uphill
