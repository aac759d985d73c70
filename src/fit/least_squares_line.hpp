// Least-squares straight lines Y = k·X + c: ordinary (the paper's fit) and weighted by u(Y).
//
// Both minimise Σ r_i²/σ_i², r_i = Y_i − c − k·X_i, with Ceres (AutoDiffCostFunction, one
// residual block of N residuals, so the cost per iteration is O(N) and no N×N matrix is formed),
// seeded with the closed form (Householder QR of the centred, standardised design, Eigen). The
// covariance comes from ceres::Covariance at the solution and is transformed back from the
// centred parameters (centre x0 = weighted mean of X, where the intercept and slope are
// uncorrelated).
//
//   OLS  σ_i = 1 (u(X), u(Y) are ignored). Reported standard errors: the usual ones,
//        s·sqrt((XᵀX)⁻¹), s² = SSR/(N − 2) (primary_scaling = kScaled); the unscaled
//        covariance is (XᵀX)⁻¹, i.e. u(Y) = 1 in Y's units. chi2 = SSR; reduced_chi2 = s²;
//        no p-value (there is no stated uncertainty to test against); residual SD =
//        sqrt(reduced_chi2). Normalised residual r_i/s.
//   WLS  σ_i = u(Y_i), required, finite and > 0; u(X) ignored. Primary: unscaled (the stated
//        uncertainties propagated); scaled = × sqrt(χ²/ν) as well. p-value of χ²_ν.
//
// Ceres stops where the cost stops changing; a Gauss-Newton refinement on the same cost function
// then takes the parameters to full precision (fit_options.hpp).
//
// Accuracy: NIST StRD "Norris" (certified to 15 digits) is reproduced to 12.8 significant
// digits in B0 and 13.6-15.5 in B1, their standard errors, the residual SD and R², from the
// closed-form seed and from a cold start alike. B0's 12.8 is the limit of the input: the
// decimal data rounded to binary64 have the exact OLS intercept -0.26232307377402675, which
// differs from the certified value in the 13th digit. Shifting X by 1e9 changes the slope by
// < 1e-12 relative (tests/fit_test.cpp).
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
