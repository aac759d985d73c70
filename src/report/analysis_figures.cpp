#include "report/analysis_figures.hpp"

#include "model/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>
#include <tuple>

namespace uphill {
namespace {

std::string Num(double v) { return Printf("%.10g", v); }

// Indices of the analysis rows in increasing X.
std::vector<size_t> ByX(const ExperimentAnalysis& a) {
  std::vector<size_t> order(a.rows.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return a.rows[i].x_eq < a.rows[j].x_eq; });
  return order;
}

// "k_ols = …; c_ols = …" in mm for a line fit that succeeded, or "".
std::string LineParameters(const ExperimentAnalysis& a, const std::string& method) {
  const FitOutcome* f = a.Fit(method);
  if (!f || !f->report) return "";
  return "k_" + method + " = " + Num(f->report->slope()) + "; c_" + method + " = " +
         Num(f->report->intercept() * 1e3) + "\n";
}

// The friction model at each trial's setting, in increasing X: x_rest(mu) (offset: minus X), mm.
std::string FrictionCurveData(const ExperimentAnalysis& a, bool offset) {
  std::ostringstream data;
  data << "\n\n# X_mm " << (offset ? "(x_rest(mu)-X)_mm" : "Y_friction_mm")
       << " (friction model at each trial's setting, increasing X)\n";
  const FitOutcome* friction = a.Fit("friction");
  if (friction && friction->report)
    for (size_t i : ByX(a))
      data << Num(a.rows[i].x_eq * 1e3) << " "
           << Num((friction->report->rows[i].fitted - (offset ? a.rows[i].x_eq : 0.0)) * 1e3) << "\n";
  return data.str();
}

// The plot clauses of the fitted models: the OLS and York lines (offset: as (k - 1)X + c) and
// the friction model read from block 1 of the figure's data file.
std::string ModelCurves(const ExperimentAnalysis& a, const std::string& data_file, bool offset) {
  std::ostringstream plot;
  const char* line = offset ? "(k_%s - 1)*x + c_%s" : "k_%s*x + c_%s";
  for (const auto& [method, label, style] :
       {std::tuple{"ols", "OLS", "lw 2 lc rgb '#d62728'"}, std::tuple{"york", "York", "lw 2 dt 4 lc rgb '#2ca02c'"}}) {
    if (!a.Fit(method)->report) continue;
    char expression[64];
    std::snprintf(expression, sizeof expression, line, method, method);
    plot << ", \\\n  " << expression << " with lines " << style << " title ";
    if (offset) {
      plot << "'" << label << " line'";
    } else {
      plot << "sprintf('" << label << ": Y = %.4f X %+.2f mm', k_" << method << ", c_" << method << ")";
    }
  }
  const FitOutcome* friction = a.Fit("friction");
  if (friction && friction->report)
    plot << ", \\\n  '" << data_file << "' index 1 using 1:2 with linespoints pt 6 ps 0.6 lw 2 lc rgb '#ff7f0e' "
         << "title sprintf('friction model, μ = %.4f', " << Num(friction->report->Parameter("mu").value) << ")";
  return plot.str();
}

// The last block of a figure's data: the excluded rows (X_mm, then `columns` of each), drawn as
// hollow grey points so that what was left out of the fits stays visible; "" when none is
// excluded. Named by its comment (kExcludedBlock) and plotted by that name: gnuplot does not count
// a block with no numbers (the friction curve's when that fit failed), so its number would shift.
constexpr const char* kExcludedBlock = "excluded from the fits";
template <typename Columns>
std::string ExcludedData(const ExperimentAnalysis& a, const std::string& header, Columns columns) {
  if (a.excluded_rows.empty()) return "";
  std::ostringstream data;
  data << "\n\n# " << kExcludedBlock << ": X_mm " << header << "\n";  // gnuplot matches the name at the start
  for (const AnalysedRow& r : a.excluded_rows) data << Num(r.x_eq * 1e3) << " " << columns(r) << "\n";
  return data.str();
}

// The plot clause of that block, or "" when no row is excluded.
std::string ExcludedPoints(const ExperimentAnalysis& a, const std::string& data_file, const std::string& using_columns,
                           const std::string& style) {
  if (a.excluded_rows.empty()) return "";
  return ", \\\n  '" + data_file + "' index '" + kExcludedBlock + "' using " + using_columns + " with " + style +
         " pt 6 ps 1.2 lw 1.5 lc rgb '#999999' title 'excluded from the fit'";
}

GnuplotFigure YAgainstX(const ExperimentAnalysis& a) {
  GnuplotFigure f;
  f.name = AnalysisFigureNames()[0];
  f.title = "Measured Y against theoretical X";
  f.caption = "Each point is one trial: X from the converter with its first-order standard uncertainty, "
              "Y as measured with u(Y). The dashed line is y = x (no friction); the straight lines are "
              "the OLS and York fits; the friction model is Y = x_rest(μ) at each trial's setting (μ: the rolling-resistance coefficient).";
  std::ostringstream data;
  data << "# X_mm Y_mm uX_mm uY_mm (one line per trial)\n";
  for (const auto& r : a.rows)
    data << Num(r.x_eq * 1e3) << " " << Num(r.y * 1e3) << " " << Num(r.u_x_eq * 1e3) << " " << Num(r.u_y * 1e3) << "\n";
  f.data = data.str() + FrictionCurveData(a, false) +
           ExcludedData(a, "Y_mm uX_mm uY_mm", [](const AnalysedRow& r) {
             return Num(r.y * 1e3) + " " + Num(r.u_x_eq * 1e3) + " " + Num(r.u_y * 1e3);
           });
  std::ostringstream plot;
  plot << LineParameters(a, "ols") << LineParameters(a, "york");
  plot << "set xlabel 'X, theoretical equilibrium (mm)'\n"
       << "set ylabel 'Y, measured farthest rest position (mm)'\n"
       << "set offsets graph 0.04, graph 0.04, graph 0.06, graph 0.04\n"
       << "plot '" << f.name << ".dat' index 0 using 1:2:3:4 with xyerrorbars pt 7 ps 0.7 lc rgb '#1f4e79' "
       << "title 'trials: Y ± u(Y), X ± u(X)', \\\n"
       << "  x with lines dt 2 lw 1.5 lc rgb '#777777' title 'y = x'" << ModelCurves(a, f.name + ".dat", false)
       << ExcludedPoints(a, f.name + ".dat", "1:2:3:4", "xyerrorbars");
  f.plot = plot.str();
  return f;
}

// The offset Y − X carries the physics (friction, and anything the model misses); on a Y-against-X
// plot it is a few millimetres on a scale of hundreds and cannot be seen.
GnuplotFigure OffsetAgainstX(const ExperimentAnalysis& a) {
  GnuplotFigure f;
  f.name = AnalysisFigureNames()[1];
  f.title = "Offset Y − X against X";
  f.caption = "The measured offset of the farthest rest position from the theoretical equilibrium, with "
              "sqrt(u(X)^2 + u(Y)^2) error bars. Zero is the frictionless model; the straight-line fits "
              "appear as (k - 1)X + c; the friction model predicts x_rest(μ) − X at each trial's setting.";
  std::ostringstream data;
  data << "# X_mm (Y-X)_mm u_mm (one line per trial)\n";
  for (const auto& r : a.rows)
    data << Num(r.x_eq * 1e3) << " " << Num((r.y - r.x_eq) * 1e3) << " " << Num(std::hypot(r.u_x_eq, r.u_y) * 1e3)
         << "\n";
  f.data = data.str() + FrictionCurveData(a, true) +
           ExcludedData(a, "(Y-X)_mm u_mm", [](const AnalysedRow& r) {
             return Num((r.y - r.x_eq) * 1e3) + " " + Num(std::hypot(r.u_x_eq, r.u_y) * 1e3);
           });
  std::ostringstream plot;
  plot << LineParameters(a, "ols") << LineParameters(a, "york");
  plot << "set xlabel 'X, theoretical equilibrium (mm)'\n"
       << "set ylabel 'Y − X (mm)'\n"
       << "set offsets graph 0.04, graph 0.04, graph 0.1, graph 0.1\n"
       << "plot '" << f.name << ".dat' index 0 using 1:2:3 with yerrorbars pt 7 ps 0.7 lc rgb '#1f4e79' "
       << "title 'trials: Y − X'";
  plot << ", \\\n  0 with lines dt 2 lw 1.5 lc rgb '#777777' title 'no friction'"
       << ModelCurves(a, f.name + ".dat", true) << ExcludedPoints(a, f.name + ".dat", "1:2:3", "yerrorbars");
  f.plot = plot.str();
  return f;
}

GnuplotFigure Residuals(const ExperimentAnalysis& a) {
  GnuplotFigure f;
  f.name = AnalysisFigureNames()[2];
  f.title = "Residuals against X";
  f.caption = "Y minus the fitted value for the OLS straight line (with u(Y) error bars) and for the "
              "friction model. Structure here (a trend or a curve) means the model misses something. Rows "
              "excluded from the fit (hollow grey) are shown against the OLS line they were not fitted to.";
  const FitOutcome* ols = a.Fit("ols");
  const FitOutcome* friction = a.Fit("friction");
  std::ostringstream data;
  data << "# X_mm residual_OLS_mm uY_mm\n";
  if (ols->report)
    for (size_t i = 0; i < a.rows.size(); ++i)
      data << Num(a.rows[i].x_eq * 1e3) << " " << Num(ols->report->rows[i].residual * 1e3) << " "
           << Num(a.rows[i].u_y * 1e3) << "\n";
  data << "\n\n# X_mm residual_friction_mm\n";
  if (friction && friction->report)
    for (size_t i = 0; i < a.rows.size(); ++i)
      data << Num(a.rows[i].x_eq * 1e3) << " " << Num(friction->report->rows[i].residual * 1e3) << "\n";
  if (ols->report)
    data << ExcludedData(a, "(Y-OLS line)_mm uY_mm", [&](const AnalysedRow& r) {
      return Num((r.y - ols->report->slope() * r.x_eq - ols->report->intercept()) * 1e3) + " " + Num(r.u_y * 1e3);
    });
  f.data = data.str();
  std::ostringstream plot;
  plot << "set xlabel 'X, theoretical equilibrium (mm)'\n"
       << "set ylabel 'residual Y − fit (mm)'\n"
       << "set offsets graph 0.04, graph 0.04, graph 0.1, graph 0.1\n"
       << "plot 0 with lines lc rgb '#777777' notitle";
  if (ols->report)
    plot << ", \\\n  '" << f.name << ".dat' index 0 using 1:2:3 with yerrorbars pt 7 ps 0.7 lc rgb '#d62728' "
         << "title 'OLS straight line'";
  if (friction && friction->report)
    plot << ", \\\n  '" << f.name << ".dat' index 1 using 1:2 with points pt 6 ps 1 lw 1.5 lc rgb '#ff7f0e' "
         << "title 'friction model'";
  if (ols->report) plot << ExcludedPoints(a, f.name + ".dat", "1:2:3", "yerrorbars");
  f.plot = plot.str();
  return f;
}

}  // namespace

std::vector<GnuplotFigure> AnalysisFigures(const ExperimentAnalysis& analysis) {
  return {YAgainstX(analysis), OffsetAgainstX(analysis), Residuals(analysis)};
}

std::vector<std::string> AnalysisFigureNames() { return {"fit_y_vs_x", "fit_offset", "fit_residuals"}; }

}  // namespace uphill
