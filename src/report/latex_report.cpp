#include "report/latex_report.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "io/atomic_file.hpp"
#include "model/number_text.hpp"
#include "report/analysis_figures.hpp"
#include "report/quoted_value.hpp"

namespace uphill {
namespace {

const char* kFits = "fits.tex";
const char* kTrials = "trials.tex";
const char* kStandalone = "report-standalone.tex";

// The fits' names in LaTeX (their titles in the HTML report carry Unicode that pdflatex refuses).
std::string FitName(const std::string& method) {
  if (method == "ols") return "Ordinary least squares (the paper's fit)";
  if (method == "wls") return "Weighted least squares";
  if (method == "york") return "York (errors in $X$ and $Y$)";
  if (method == "robust") return "Robust (Huber loss)";
  return "Rolling resistance, $Y = x_\\mathrm{rest}(\\mu)$";
}

// \num{value(u)} of a parameter, scaled (1e3: m → mm), or "--" when the fit has none.
std::string Parameter(const FitReport& r, const std::string& name, double scale) {
  for (const ParameterEstimate& p : r.parameters) {
    if (p.name != name) continue;
    const auto se = r.StandardError(name, r.primary_scaling);
    return "\\num{" + QuoteValue(p.value * scale, se ? *se * scale : 0.0).concise + "}";
  }
  return "--";
}

std::string Num(const std::optional<double>& v, const char* format) {
  return v ? "\\num{" + Printf(format, *v) + "}" : "--";
}

// X ± u(X) and the like, in mm.
std::string Millimetres(double value, double u) { return "\\num{" + QuoteValue(value * 1e3, u * 1e3).concise + "}"; }

std::string FigureCaption(const std::string& name) {
  if (name == "fit_y_vs_x")
    return "Measured rest position $Y$ against the theoretical equilibrium $X$, with the straight-line fits and "
           "the rolling-resistance model. Hollow grey points: excluded from the fits.";
  if (name == "fit_offset")
    return "The offset $Y - X$ against $X$: zero is the model without rolling resistance.";
  return "Residuals of the ordinary least-squares line and of the rolling-resistance model.";
}

}  // namespace

std::string LatexEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '\\': out += "\\textbackslash{}"; break;
      case '&': case '%': case '$': case '#': case '_': case '{': case '}':
        out += '\\';
        out += c;
        break;
      case '~': out += "\\textasciitilde{}"; break;
      case '^': out += "\\textasciicircum{}"; break;
      case '\n': case '\r': case '\t': out += ' '; break;
      default: out += c;
    }
  }
  return out;
}

std::string LatexFitsTable(const ExperimentAnalysis& a) {
  std::ostringstream t;
  t << "% fits.tex: the fits of Y against X, written by `uphill report --latex` (needs \\usepackage{siunitx}).\n"
    << "% Standard errors in parentheses, in units of the last digit (scaled by sqrt(chi2/nu) for OLS, else\n"
    << "% from the stated uncertainties); lengths in mm. The OLS chi2 is a residual sum of squares: not shown.\n"
    << "\\begin{tabular}{lrrrrrr}\n\\hline\n"
    << "Fit & $k$ & $c$ (\\si{\\milli\\metre}) & $\\mu$ & $\\chi^2/\\nu$ & $p$ & AIC \\\\\n\\hline\n";
  for (const FitOutcome& f : a.fits) {
    t << FitName(f.method);
    if (!f.report) {
      t << " & \\multicolumn{6}{l}{not available} \\\\\n";
      continue;
    }
    const FitReport& r = *f.report;
    const bool ols = r.method == FitMethod::kOrdinaryLeastSquares;
    t << " & " << Parameter(r, "k", 1.0) << " & " << Parameter(r, "c", 1e3) << " & " << Parameter(r, "mu", 1.0) << " & "
      << (ols ? "--" : Num(r.reduced_chi2, "%.3g")) << " & " << Num(r.p_value, "%.3g") << " & " << Num(r.aic, "%.2f")
      << " \\\\\n";
  }
  t << "\\hline\n\\end{tabular}\n";
  return t.str();
}

std::string LatexTrialsTable(const ExperimentAnalysis& a) {
  std::ostringstream t;
  t << "% trials.tex: the trials, written by `uphill report --latex` (needs \\usepackage{siunitx}).\n"
    << "% X with its first-order standard uncertainty, Y with u(Y), in parentheses in units of the last digit.\n"
    << "\\begin{tabular}{llrrrrrl}\n\\hline\n"
    << "Trial & Series & $\\theta$ (\\si{\\degree}) & $\\alpha$ (\\si{\\degree}) & $X$ (\\si{\\milli\\metre}) & "
    << "$Y$ (\\si{\\milli\\metre}) & $Y - X$ (\\si{\\milli\\metre}) & Fit \\\\\n\\hline\n";
  std::vector<const AnalysedRow*> rows;
  for (const AnalysedRow& r : a.rows) rows.push_back(&r);
  for (const AnalysedRow& r : a.excluded_rows) rows.push_back(&r);
  std::stable_sort(rows.begin(), rows.end(),
                   [](const AnalysedRow* p, const AnalysedRow* q) { return p->source->row < q->source->row; });
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  for (const AnalysedRow* r : rows) {
    t << LatexEscape(r->source->trial) << " & " << LatexEscape(r->source->series) << " & \\num{"
      << Printf("%.3f", r->theta * kDegrees) << "} & \\num{" << Printf("%.3f", r->alpha * kDegrees) << "} & "
      << Millimetres(r->x_eq, r->u_x_eq) << " & " << Millimetres(r->y, r->u_y) << " & \\num{"
      << Printf("%.2f", (r->y - r->x_eq) * 1e3) << "} & "
      << (r->source->excluded.empty() ? "yes" : "excluded: " + LatexEscape(r->source->excluded)) << " \\\\\n";
  }
  t << "\\hline\n\\end{tabular}\n";
  return t.str();
}

std::string LatexStandalone(const ExperimentAnalysis& a) {
  const Experiment& e = *a.experiment;
  std::ostringstream t;
  t << "% report-standalone.tex, written by `uphill report --latex`: pdflatex report-standalone.tex\n"
    << "\\documentclass[a4paper]{article}\n\\usepackage[T1]{fontenc}\n\\usepackage[utf8]{inputenc}\n"
    << "\\usepackage{siunitx}\n\\usepackage{graphicx}\n\\begin{document}\n"
    << "\\section*{" << LatexEscape(e.title.empty() ? "Fit report" : e.title) << "}\n"
    << "\\begin{table}[htbp]\n\\centering\n"
    << "\\caption{Fits of the measured rest position $Y$ against the theoretical equilibrium $X$.}\n"
    << "\\resizebox{\\linewidth}{!}{\\input{" << kFits << "}}\n\\end{table}\n"
    << "\\begin{table}[htbp]\n\\centering\n\\caption{The trials.}\n"
    << "\\resizebox{\\linewidth}{!}{\\input{" << kTrials << "}}\n\\end{table}\n";
  for (const std::string& name : AnalysisFigureNames())
    t << "\\begin{figure}[htbp]\n\\centering\n\\includegraphics[width=\\linewidth]{" << name << ".pdf}\n\\caption{"
      << FigureCaption(name) << "}\n\\end{figure}\n";
  t << "\\end{document}\n";
  return t.str();
}

void WriteLatexFiles(const ExperimentAnalysis& a, const std::string& directory) {
  const std::filesystem::path dir(directory);
  WriteFileAtomically((dir / kFits).string(), LatexFitsTable(a));
  WriteFileAtomically((dir / kTrials).string(), LatexTrialsTable(a));
  WriteFileAtomically((dir / kStandalone).string(), LatexStandalone(a));
}

std::vector<std::string> LatexFiles() { return {kFits, kTrials, kStandalone}; }

}  // namespace uphill
