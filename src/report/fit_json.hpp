// JSON of fits and analyses (SI units: metres, radians). Documented in docs/fit.md, "fit.json".
//
// FitToJson(report) is the stable machine interface of `uphill fit --xy … --json`: for a straight
// line the top-level keys `slope`, `intercept`, `u_slope`, `u_intercept` (the method's primary
// convention: the usual OLS standard errors for ols, unscaled for wls/york/robust), `chi2`, `dof`,
// `p_value` (null when not defined), `n`, then the full detail: parameters in both conventions,
// covariance, correlation, reduced χ², AIC/BIC, per-row residuals and flags, notes, solver.
#pragma once

#include <nlohmann/json.hpp>

#include <ostream>

#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"
#include "report/analysis.hpp"

namespace uphill {

inline constexpr const char* kFitJsonFormat = "uphill-fit/1";

nlohmann::ordered_json FitToJson(const FitReport& report);

// FitToJson(report).dump(2) written to `out`, with the per-row entries of `rows` streamed from
// the fit and its data (LineRowResults, fit/line_rows.hpp) when the fit did not keep them
// (FitOptions::keep_rows = false): one compact object per line, never one JSON tree of N
// objects, so that memory does not grow with N. with_rows = false writes "rows": [] (the
// summaries, outliers and down-weighted rows stay). Numbers are printed shortest round-trip, as
// nlohmann::json prints them.
void WriteFitJson(std::ostream& out, const FitReport& report, const LineData& data, bool with_rows = true);
nlohmann::ordered_json AnalysisToJson(const ExperimentAnalysis& analysis);

}  // namespace uphill
