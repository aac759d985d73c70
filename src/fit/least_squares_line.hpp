// Least-squares straight lines Y = k·X + c: ordinary (the paper's fit) and weighted by u(Y).
//
// Both minimise Σ r_i²/σ_i², r_i = Y_i − c − k·X_i. The criterion is quadratic, so it is fixed by
// six weighted moments of the standardised data (internal/least_squares_moments.hpp), taken in one
// vectorised pass: the closed form is one Gauss-Newton step from them (seed_with_closed_form, the
// default: exact, Ceres has nothing to iterate), and Ceres solves from a cold start
// (seed_with_closed_form = false) on the N rows compressed to 3 residuals with the same cost,
// gradient and Gauss-Newton matrix (internal/compressed_cost.hpp, as York's fit). The covariance
// is ceres::Covariance of that compressed problem (whose Jacobian has the N-row Jacobian's singular
// values), transformed back from the standardised parameters. A second pass over the rows gives
// χ² and the per-row results (FitOptions::keep_rows; line_rows.hpp).
//
//   OLS  σ_i = 1 (u(X), u(Y) are ignored). Reported standard errors: the usual ones,
//        s·sqrt((XᵀX)⁻¹), s² = SSR/(N − 2) (primary_scaling = kScaled); the unscaled
//        covariance is (XᵀX)⁻¹, i.e. u(Y) = 1 in Y's units. chi2 = SSR; reduced_chi2 = s²;
//        no p-value (there is no stated uncertainty to test against); residual SD =
//        sqrt(reduced_chi2). Normalised residual r_i/s.
//   WLS  σ_i = u(Y_i), required, finite and > 0; u(X) ignored. Primary: unscaled (the stated
//        uncertainties propagated); scaled = × sqrt(χ²/ν) as well. p-value of χ²_ν.
//
// After Ceres, Newton's step from the moments (exact for a quadratic) takes the parameters to full
// precision (fit_options.hpp).
//
// Accuracy: NIST StRD "Norris" (certified to 15 digits) is reproduced to 12.8 significant
// digits in B0 and 13.6-15.5 in B1, their standard errors, the residual SD and R², from the
// closed-form seed and from a cold start alike. B0's 12.8 is the limit of the input: the
// decimal data rounded to binary64 have the exact OLS intercept -0.26232307377402675, which
// differs from the certified value in the 13th digit. Against the 50-digit closed form (src/oracle)
// every parameter and standard error agrees to ~1e-15 relative, at 10^6 rows too (`uphill bench
// fit`). Shifting X by 1e9 changes the slope by
// < 1e-12 relative (tests/fit_certified_test.cpp, tests/fit_oracle_test.cpp).
// N = 2: the exact line, exact = true, ν = 0, with a note; OLS then has no standard error.
// Errors: InputError from ValidateLineData (N < 2, all X equal, non-finite values; WLS: u(Y)
// missing, non-finite or ≤ 0).
#pragma once

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

FitReport FitOrdinaryLeastSquares(const LineData& data, const FitOptions& options = {});
FitReport FitWeightedLeastSquares(const LineData& data, const FitOptions& options = {});

}  // namespace uphill
