// JSON of fits and analyses (SI units: metres, radians). Documented in README.md, "fit.json".
//
// FitToJson(report) is the stable machine interface of `uphill fit --xy … --json`: for a straight
// line the top-level keys `slope`, `intercept`, `u_slope`, `u_intercept` (the method's primary
// convention: the usual OLS standard errors for ols, unscaled for wls/york/robust), `chi2`, `dof`,
// `p_value` (null when not defined), `n`, then the full detail: parameters in both conventions,
// covariance, correlation, reduced χ², AIC/BIC, per-row residuals and flags, notes, solver.
#pragma once

#include <nlohmann/json.hpp>

#include "fit/fit_report.hpp"
#include "report/analysis.hpp"

namespace uphill::report {

inline constexpr const char* kFitJsonFormat = "uphill-fit/1";

nlohmann::ordered_json FitToJson(const FitReport& report);
nlohmann::ordered_json AnalysisToJson(const ExperimentAnalysis& analysis);

}  // namespace uphill::report
