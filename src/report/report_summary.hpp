// ReportSummary: what the top of a report says, in plain words — the number to quote, why that
// model, and what to look at before quoting it.
//
// Which number (from the comparison AnalyseExperiment makes, fit/model_comparison.hpp: the
// friction model Y = x_rest(μ) against the straight line Y = k·X + c fitted to the same rows with
// the same uncertainties, York's line when u(X) is known):
//   both AIC and BIC lower for friction   quote μ, the rolling-resistance coefficient, ± its
//                                         standard error (the friction fit's primary convention)
//   both lower for the line               quote the compared line's slope k and intercept c
//   AIC and BIC disagree                  the data do not decide: quote both
//   no comparison (the friction fit is    quote the best line available: York (uncertainties in
//   unavailable: a double cone, no u(Y))  X and Y), else WLS, else OLS, and say why
// How strongly (Burnham & Anderson, as fit/model_comparison.hpp): |ΔAIC| > 10 decisive, > 2
// clear, else slight. When the preferred fit's p-value is below 0.001 the summary says that even
// it scatters beyond the stated uncertainties.
// Numbers are rounded to their uncertainty (quoted_value.hpp); lengths in mm.
//
// Also: every fitted row that carries a row-check flag (row_check.hpp: a flagged row stays in
// the fit until the technician excludes it), and every excluded row with its reason.
#pragma once

#include <string>
#include <vector>

#include "report/analysis.hpp"

namespace uphill {

struct ReportSummary {
  // "friction", the compared line's method ("york", "wls", "ols"), "both" (AIC and BIC
  // disagree), or "" when nothing could be fitted.
  std::string preferred;
  std::vector<std::string> quote;     // one line per number to quote ("… μ = 0.0503 ± 0.0012")
  std::string why;                    // the reason in words
  std::vector<std::string> flagged;   // fitted rows with flags: "trial t3 (row 4): message; …"
  std::vector<std::string> excluded;  // excluded rows: "trial t5 (row 6): reason"
};

ReportSummary SummariseAnalysis(const ExperimentAnalysis& analysis);

}  // namespace uphill
