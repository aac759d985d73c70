#include "report/report_summary.hpp"

#include <cmath>

#include "model/number_text.hpp"
#include "report/quoted_value.hpp"

namespace uphill {
namespace {

std::string LineName(const std::string& method) {
  if (method == "york") return "York's straight line (uncertainties in X and Y)";
  if (method == "wls") return "the weighted least-squares line (u(Y))";
  return "the ordinary least-squares line (the paper's fit)";
}

QuotedValue Quote(const FitReport& r, const std::string& name, double scale) {
  const auto se = r.StandardError(name, r.primary_scaling);
  return QuoteValue(r.Parameter(name).value * scale, se ? *se * scale : 0.0);
}

std::string MuLine(const FitReport& friction) {
  return "rolling-resistance coefficient μ = " + Quote(friction, "mu", 1.0).PlusMinus() +
         " (friction model Y = x_rest(μ))";
}

std::string LineLine(const FitReport& line, const std::string& method) {
  return "slope k = " + Quote(line, "k", 1.0).PlusMinus() + " and intercept c = " + Quote(line, "c", 1e3).PlusMinus() +
         " mm of " + LineName(method) + ", Y = k·X + c";
}

std::string Strength(double delta_aic) {
  const double d = std::abs(delta_aic);
  if (d > 10) return "decisively";
  if (d > 2) return "clearly";
  return "only slightly (a difference below 2 is not worth noting)";
}

std::string Parameters(const FitReport& r) {
  const std::size_t n = r.parameters.size();
  return std::to_string(n) + (n == 1 ? " parameter" : " parameters");
}

// A sentence when even the preferred fit scatters beyond its stated uncertainties.
std::string Scatter(const FitReport& r) {
  if (!r.p_value || *r.p_value >= 1e-3 || !r.reduced_chi2) return "";
  return " Even so, it scatters more than the stated uncertainties allow (χ²/ν = " + Printf("%.3g", *r.reduced_chi2) +
         ", p = " + Printf("%.2g", *r.p_value) +
         "): check u(Y) and the setting's uncertainties, or look for what the model misses.";
}

void Compared(const ExperimentAnalysis& a, const FitReport& friction, ReportSummary* s) {
  const ModelComparison& c = *a.friction_vs_line;
  const FitOutcome* line = a.Fit(c.first);
  const std::string line_name = c.first == "york" ? "York's straight line" : c.first == "wls" ? "the weighted line"
                                                                                           : "the OLS line";
  const std::string counts = "the friction model (" + Parameters(friction) + ", μ) and " + line_name +
                             " (2 parameters, k and c)";
  // What decides: a better fit, or as good a fit with fewer parameters (which AIC and BIC reward).
  const std::string fit_words = c.delta_chi2 <= 0 ? "fits the trials at least as well with fewer parameters"
                                                  : "fits the trials almost as well (a slightly larger χ²) with fewer "
                                                    "parameters, which AIC and BIC reward";
  const std::string numbers = Printf(" (ΔAIC = %.3g", c.delta_aic) + Printf(", ΔBIC = %.3g", c.delta_bic) +
                              Printf(", χ² = %.4g for friction", friction.chi2) +
                              Printf(" and %.4g for the line", friction.chi2 - c.delta_chi2) +
                              " for " + std::to_string(friction.n) + " trials)";
  if (c.delta_aic < 0 && c.delta_bic < 0) {
    s->preferred = "friction";
    s->quote.push_back(MuLine(friction));
    s->why = "Both AIC and BIC prefer the friction model, " + Strength(c.delta_aic) + ": fitted to the same trials, " +
             counts + ", the friction model " + fit_words + numbers + "." + Scatter(friction);
  } else if (c.delta_aic > 0 && c.delta_bic > 0 && line && line->report) {
    s->preferred = c.first;
    s->quote.push_back(LineLine(*line->report, c.first));
    s->why = "Both AIC and BIC prefer the straight line, " + Strength(c.delta_aic) + ": fitted to the same trials, " +
             counts + ", the rest positions follow a line better than the rolling-resistance model" + numbers +
             ". μ of the friction fit is in the fit table, but these data do not support the model." +
             Scatter(*line->report);
  } else {
    s->preferred = "both";
    s->quote.push_back(MuLine(friction));
    if (line && line->report) s->quote.push_back(LineLine(*line->report, c.first));
    s->why = "AIC and BIC disagree about " + counts + numbers +
             ": the data do not decide between the models, so quote both and say so.";
  }
}

}  // namespace

ReportSummary SummariseAnalysis(const ExperimentAnalysis& a) {
  ReportSummary s;
  const FitOutcome* friction = a.Fit("friction");
  if (a.friction_vs_line && friction && friction->report) {
    Compared(a, *friction->report, &s);
  } else {
    for (const char* method : {"york", "wls", "ols"}) {
      const FitOutcome* line = a.Fit(method);
      if (!line || !line->report) continue;
      s.preferred = method;
      s.quote.push_back(LineLine(*line->report, method));
      std::string reason = friction && !friction->unavailable.empty() ? " (" + friction->unavailable + ")" : "";
      s.why = "The friction model could not be fitted and compared" + reason + ", so the straight line is quoted: " +
              LineName(method) + ", the best line these data allow (York needs u(X) and u(Y), WLS u(Y))." +
              Scatter(*line->report);
      break;
    }
    if (s.preferred.empty())
      s.why = a.rows.empty() ? "Nothing is fitted: every usable row is excluded from the fit."
                             : "No fit could be made (each fit's reason is in the fit table).";
  }
  for (const AnalysedRow& r : a.rows) {
    if (r.flags.empty()) continue;
    std::string messages;
    for (const RowFlag& f : r.flags) messages += (messages.empty() ? "" : "; ") + f.message;
    s.flagged.push_back("trial " + r.source->trial + " (row " + std::to_string(r.source->row) + "): " + messages);
  }
  for (const AnalysedRow& r : a.excluded_rows)
    s.excluded.push_back("trial " + r.source->trial + " (row " + std::to_string(r.source->row) + "): " + r.source->excluded);
  return s;
}

}  // namespace uphill
