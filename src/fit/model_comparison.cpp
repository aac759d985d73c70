#include "fit/model_comparison.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "model/input_error.hpp"

namespace uphill {

void SetInformationCriteria(FitReport& report, double sum_log_sigma2) {
  report.aic.reset();
  report.bic.reset();
  if (report.method == FitMethod::kRobust) return;  // no Gaussian likelihood
  const double n = static_cast<double>(report.n);
  double p = static_cast<double>(report.parameters.size());
  double minus_two_log_l = 0.0;
  if (report.uses_stated_uncertainties) {
    minus_two_log_l = report.chi2 + n * std::log(2.0 * std::numbers::pi) + sum_log_sigma2;
  } else {
    // σ estimated by maximum likelihood, σ̂² = SSR/N: one more parameter.
    if (!(report.chi2 > 0.0)) return;  // exact fit: the likelihood is unbounded
    minus_two_log_l = n * (std::log(2.0 * std::numbers::pi * report.chi2 / n) + 1.0);
    p += 1.0;
  }
  report.aic = minus_two_log_l + 2.0 * p;
  report.bic = minus_two_log_l + p * std::log(n);
}

ModelComparison CompareModels(const FitReport& first, const FitReport& second) {
  if (first.n != second.n)
    throw InputError("fits", "compare fits of the same rows (" + std::to_string(first.n) + " and " +
                                 std::to_string(second.n) + " rows)");
  if (first.uses_stated_uncertainties != second.uses_stated_uncertainties)
    throw InputError("fits",
                     "compare fits that both use the stated u(Y) or both estimate the "
                     "scatter (" +
                         MethodName(first.method) + " and " + MethodName(second.method) +
                         " differ)");
  if (!first.aic || !first.bic || !second.aic || !second.bic)
    throw InputError("fits",
                     "AIC/BIC need a Gaussian likelihood with a non-zero scatter "
                     "(not a robust fit, not an exact fit without stated u(Y))");
  ModelComparison c;
  c.first = MethodName(first.method);
  c.second = MethodName(second.method);
  c.delta_chi2 = second.chi2 - first.chi2;
  c.delta_aic = *second.aic - *first.aic;
  c.delta_bic = *second.bic - *first.bic;
  c.akaike_weight_second = 1.0 / (1.0 + std::exp(c.delta_aic / 2.0));
  const auto prefers = [&](double delta) { return delta < 0.0 ? c.second : c.first; };
  std::ostringstream verdict;
  verdict.precision(4);
  if (prefers(c.delta_aic) == prefers(c.delta_bic))
    verdict << "AIC and BIC prefer " << prefers(c.delta_aic);
  else
    verdict << "AIC prefers " << prefers(c.delta_aic) << ", BIC prefers " << prefers(c.delta_bic);
  verdict << " (dAIC = " << c.delta_aic << ", dBIC = " << c.delta_bic << ", " << c.second
          << " minus " << c.first << ")";
  c.verdict = verdict.str();
  return c;
}

}  // namespace uphill
