// Comparing two fits of the same rows: χ², AIC and BIC.
//
// Information criteria of a Gaussian likelihood with p fitted parameters, N rows:
//   stated σ_i (uses_stated_uncertainties):  −2 ln L = χ² + Σ ln(2π σ_i²),   p_eff = p
//   σ estimated (OLS-like, σ̂² = SSR/N):      −2 ln L = N·(ln(2π σ̂²) + 1),    p_eff = p + 1
//   AIC = −2 ln L + 2·p_eff,   BIC = −2 ln L + p_eff·ln N.
// (York: σ_i² = u(Y)² + k²u(X)², the effective variance at the fitted slope.) Lower is better;
// a difference of more than ~2 is worth noting, more than ~10 is decisive (Burnham & Anderson;
// Kass & Raftery for BIC). Robust fits have no Gaussian likelihood and no AIC/BIC. An exact
// fit with estimated σ (SSR = 0) has none either.
//
// CompareModels requires both fits to describe the same rows (same N) with the same kind of σ
// (both stated or both estimated); it is the caller's duty that the stated σ_i are the same.
#pragma once

#include <string>

#include "fit/fit_report.hpp"

namespace uphill {

struct ModelComparison {
  std::string first, second;  // MethodName of each fit
  double delta_chi2 = 0.0;    // χ²(second) − χ²(first)
  double delta_aic = 0.0;     // AIC(second) − AIC(first): negative prefers the second
  double delta_bic = 0.0;
  // exp(−ΔAIC/2)/(1 + exp(−ΔAIC/2)): the Akaike weight of the second model in the pair.
  double akaike_weight_second = 0.5;
  std::string verdict;  // one line, e.g. "AIC and BIC prefer friction (ΔAIC = −12.3, ...)"
};

// Throws InputError when the fits are not comparable (see above).
ModelComparison CompareModels(const FitReport& first, const FitReport& second);

// Fills aic/bic of `report` from chi2, n, parameters and the σ_i (see above). Used by the fits;
// exposed so that a caller assembling a report elsewhere computes them the same way.
// sum_log_sigma2 = Σ ln σ_i² (ignored unless report.uses_stated_uncertainties).
void SetInformationCriteria(FitReport& report, double sum_log_sigma2);

}  // namespace uphill
