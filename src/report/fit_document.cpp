#include "report/fit_document.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>

#include "io/atomic_file.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "report/analysis_figures.hpp"
#include "report/fit_json.hpp"
#include "report/gnuplot_figure.hpp"
#include "report/latex_report.hpp"
#include "report/report_summary.hpp"
#include "report/video_report.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

// The terminal columns a UTF-8 text takes: one per code point (θ, χ², ± are one column each).
size_t Columns(const std::string& text) {
  size_t n = 0;
  for (const char c : text) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return n;
}

std::string Mm(double m, const char* format = "%.2f") { return Printf(format, m * 1e3); }
std::string Deg(double rad) { return Printf("%.3f", rad * 180.0 / std::numbers::pi); }
std::string Opt(const std::optional<double>& v, const char* format) { return v ? Printf(format, *v) : "-"; }

// {"a": "15.875 mm", "type": "spheroid"} -> "type = spheroid, a = 15.875 mm" (type first).
std::string KeyValues(const nlohmann::json& object) {
  std::string out;
  const auto add = [&](const std::string& key, const nlohmann::json& v) {
    out += (out.empty() ? "" : ", ") + key + " = " + (v.is_string() ? v.get<std::string>() : v.dump());
  };
  if (object.contains("type")) add("type", object.at("type"));
  for (const auto& [key, v] : object.items())
    if (key != "type") add(key, v);
  return out;
}

std::string ParameterText(const FitReport& r, const ParameterEstimate& p) {
  const bool length = p.name == "c";
  if (p.name == "mu") {  // the rolling-resistance coefficient, as the summary names it
    const auto primary = r.StandardError(p.name, r.primary_scaling);
    return "μ = " + Printf("%.6g", p.value) + (primary ? " ± " + Printf("%.6g", *primary) : "");
  }
  const auto show = [&](double v) { return length ? Mm(v, "%.3f") + " mm" : Printf("%.6g", v); };
  const auto primary = r.StandardError(p.name, r.primary_scaling);
  return p.name + " = " + show(p.value) + (primary ? " ± " + show(*primary) : " (no uncertainty: exact fit)");
}

Table FitTable(const ExperimentAnalysis& a) {
  Table t;
  t.header = {"fit", "parameters (± standard error)", "s.e. convention", "χ²", "ν", "χ²/ν", "p-value",
              "AIC", "BIC", "flagged rows"};
  for (const FitOutcome& f : a.fits) {
    if (!f.report) {
      t.rows.push_back({f.title, "not available: " + f.unavailable, "", "", "", "", "", "", "", ""});
      continue;
    }
    const FitReport& r = *f.report;
    std::string params;
    for (const auto& p : r.parameters) params += (params.empty() ? "" : "; ") + ParameterText(r, p);
    std::string flagged;
    for (size_t i : r.outliers) flagged += (flagged.empty() ? "outliers: " : ", ") + a.rows[i].source->trial;
    for (const auto& d : r.downweighted)
      flagged += std::string(flagged.empty() ? "" : "; ") + "down-weighted " + a.rows[d.row].source->trial +
                 " (w = " + Printf("%.2f", d.weight) + ")";
    const bool scaled = r.primary_scaling == ErrorScaling::kScaled;
    // OLS has no stated uncertainties: its chi2 is the residual sum of squares, in m² → mm².
    const bool ols = r.method == FitMethod::kOrdinaryLeastSquares;
    const std::string chi2 = ols ? "RSS " + Printf("%.4g", r.chi2 * 1e6) + " mm²" : Printf("%.4g", r.chi2);
    const std::string reduced = ols ? (r.reduced_chi2 ? "s² " + Printf("%.3g", *r.reduced_chi2 * 1e6) + " mm²" : "-")
                                    : Opt(r.reduced_chi2, "%.3g");
    t.rows.push_back({f.title, params, scaled ? "scaled by √(χ²/ν)" : "unscaled (stated u)",
                      chi2, std::to_string(r.dof), reduced,
                      Opt(r.p_value, "%.3g"), Opt(r.aic, "%.2f"), Opt(r.bic, "%.2f"), flagged});
  }
  return t;
}

// The fitted and the excluded rows in file order; an excluded row has no residuals and says why.
Table RowTable(const ExperimentAnalysis& a) {
  Table t;
  t.header = {"trial", "series", "θ (°)", "α (°)", "X (mm)", "u(X) 1st (mm)", "u(X) MC (mm)",
              "Y (mm)", "u(Y) (mm)", "Y − X (mm)"};
  const FitOutcome* ols = a.Fit("ols");
  const FitOutcome* york = a.Fit("york");
  const bool with_ols = ols && ols->report, with_york = york && york->report;
  if (with_ols) t.header.push_back("OLS residual (mm)");
  if (with_york) t.header.push_back("York norm. residual");
  t.header.push_back("flags");
  std::vector<std::pair<const AnalysedRow*, std::optional<size_t>>> order;  // row, index among the fitted
  for (size_t i = 0; i < a.rows.size(); ++i) order.emplace_back(&a.rows[i], i);
  for (const AnalysedRow& r : a.excluded_rows) order.emplace_back(&r, std::nullopt);
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& p, const auto& q) { return p.first->source->row < q.first->source->row; });
  for (const auto& [r, fitted] : order) {
    std::vector<std::string> row = {r->source->trial, r->source->series, Deg(r->theta), Deg(r->alpha), Mm(r->x_eq),
                                    Mm(r->u_x_eq, "%.3f"), Mm(r->u_x_eq_mc, "%.3f"), Mm(r->y), Mm(r->u_y, "%.3f"),
                                    Mm(r->y - r->x_eq)};
    std::string flags = fitted ? "" : "excluded from the fit: " + r->source->excluded;
    for (const RowFlag& f : r->flags) flags += (flags.empty() ? "" : "; ") + f.message;
    if (with_ols) {
      row.push_back(fitted ? Mm(ols->report->rows[*fitted].residual) : "-");
      if (fitted && ols->report->rows[*fitted].outlier) flags += std::string(flags.empty() ? "" : "; ") + "OLS outlier";
    }
    if (with_york) {
      row.push_back(fitted ? Printf("%.2f", york->report->rows[*fitted].normalised) : "-");
      if (fitted && york->report->rows[*fitted].outlier) flags += std::string(flags.empty() ? "" : "; ") + "York outlier";
    }
    row.push_back(flags);
    t.rows.push_back(row);
  }
  return t;
}

// What the analysis used, and the straight lines' numbers as the paper states them.
std::string Overview(const ExperimentAnalysis& a) {
  std::ostringstream s;
  s << a.rows.size() << " trials fitted";
  if (!a.excluded_rows.empty()) s << ", " << a.excluded_rows.size() << " excluded from the fit (listed above)";
  if (!a.row_errors.empty()) s << " (" << a.row_errors.size() << " rows left out as unusable, listed below)";
  s << ". ";
  if (const FitOutcome* ols = a.Fit("ols"); ols && ols->report) {
    const FitReport& r = *ols->report;
    s << "The paper's fit (OLS) gives Y = " << Printf("%.4f", r.slope()) << "·X " << (r.intercept() < 0 ? "− " : "+ ")
      << Mm(std::abs(r.intercept())) << " mm";
    if (const auto se = r.StandardError("k", r.primary_scaling)) s << " (slope ± " << Printf("%.4f", *se) << ")";
    s << ". ";
  }
  if (const FitOutcome* york = a.Fit("york"); york && york->report) {
    const FitReport& r = *york->report;
    s << "With the uncertainties of both X and Y (York): slope " << Printf("%.4f", r.slope()) << ", intercept "
      << Mm(r.intercept()) << " mm, χ²/ν = " << Opt(r.reduced_chi2, "%.2f") << ". ";
  }
  return s.str();
}

// The top of the report: the number to quote and why, then what to check before quoting it.
void AddSummary(const ExperimentAnalysis& a, Document* d) {
  const ReportSummary s = SummariseAnalysis(a);
  d->Heading("Summary");
  if (!s.quote.empty()) {
    d->Paragraph(s.quote.size() == 1 ? "Quote: " + s.quote.front() + "." : "Quote both:");
    if (s.quote.size() > 1) d->List(s.quote);
  }
  d->Paragraph("Why: " + s.why);
  if (!s.flagged.empty()) {
    d->Paragraph("Warning: " + std::to_string(s.flagged.size()) + (s.flagged.size() == 1 ? " row is" : " rows are") +
                 " flagged but still in the fit. Check each; if the flag is right, exclude the row (the excluded "
                 "column of measurements.csv, or the page's toggle) and write the report again:");
    d->List(s.flagged);
  }
  if (!s.excluded.empty()) {
    d->Paragraph("Excluded from the fit (shown in the table and as hollow grey points in the figures, not fitted):");
    d->List(s.excluded);
  }
  d->Paragraph(Overview(a));
}

}  // namespace

Document FitDocument(const ExperimentAnalysis& a, bool with_figures) {
  const Experiment& e = *a.experiment;
  Document d;
  d.title = "Fit report: " + (e.title.empty() ? e.directory : e.title);
  AddSummary(a, &d);
  d.Heading("Setup");
  std::vector<std::string> setup = {"Experiment folder: " + e.directory};
  if (!e.operator_name.empty()) setup.push_back("Operator: " + e.operator_name);
  if (!e.date.empty()) setup.push_back("Date: " + e.date);
  const auto& meta = e.metadata;
  setup.push_back("Body: " + KeyValues(meta.at("body")));
  if (meta.contains("apparatus")) setup.push_back("Apparatus constants: " + KeyValues(meta.at("apparatus")));
  if (meta.contains("uncertainties"))
    setup.push_back("Default standard uncertainties: " + KeyValues(meta.at("uncertainties")));
  setup.push_back("Conventions: x horizontal from O (the rails' meeting point); tan θ = H/L and "
                  "tan(α/2) = D/(2L) with L horizontal unless the L convention says along-rail. "
                  "X is the theoretical unstable equilibrium, Y the measured farthest rest position.");
  d.List(setup);
  if (!e.notes.empty()) {
    d.Heading("Notes");
    std::istringstream notes(e.notes);
    for (std::string line; std::getline(notes, line);) d.Paragraph(line);
  }
  if (with_figures) {
    d.Heading("Figures");
    for (const GnuplotFigure& f : AnalysisFigures(a)) d.Figure(f.name, f.title, f.caption);
  }
  d.Heading("Fits of Y against X");
  d.AddTable(FitTable(a));
  d.Paragraph("Standard errors: 'unscaled' come from the stated uncertainties alone; 'scaled' are multiplied by "
              "√(χ²/ν) (fit.json has both for every fit). The p-value is the probability of a χ² at "
              "least this large if the model and the stated uncertainties are right. μ is the rolling-resistance "
              "coefficient of the friction model Y = x_rest(μ): the body rests where |dz/dx| ≤ μ.");
  d.List(a.notes);
  for (const FitOutcome& f : a.fits)
    if (f.report)
      for (const auto& note : f.report->notes) d.List({f.method + ": " + note});
  d.Heading("Trials");
  d.AddTable(RowTable(a));
  AddVideoSections(a, with_figures, &d);
  if (!a.row_errors.empty()) {
    d.Heading("Rows left out");
    d.List(a.row_errors);
  }
  return d;
}

std::string RenderText(const Document& d) {
  std::ostringstream o;
  o << d.title << "\n" << std::string(d.title.size(), '=') << "\n\n";
  for (const Block& b : d.blocks) {
    switch (b.kind) {
      case Block::Kind::kHeading: o << b.text << "\n" << std::string(b.text.size(), '-') << "\n"; break;
      case Block::Kind::kParagraph: o << b.text << "\n\n"; break;
      case Block::Kind::kList:
        for (const auto& item : b.items) o << "  * " << item << "\n";
        o << "\n";
        break;
      case Block::Kind::kFigure: break;
      case Block::Kind::kTable: {
        std::vector<size_t> width(b.table.header.size());
        for (size_t i = 0; i < width.size(); ++i) width[i] = Columns(b.table.header[i]);
        for (const auto& row : b.table.rows)
          for (size_t i = 0; i < row.size() && i < width.size(); ++i) width[i] = std::max(width[i], Columns(row[i]));
        const auto print = [&](const std::vector<std::string>& row) {
          for (size_t i = 0; i < row.size(); ++i)
            o << (i ? "  " : "") << row[i] << (i + 1 < row.size() ? std::string(width[i] - Columns(row[i]), ' ') : "");
          o << "\n";
        };
        print(b.table.header);
        for (const auto& row : b.table.rows) print(row);
        o << "\n";
        break;
      }
    }
  }
  return o.str();
}

std::vector<std::string> FitReportFiles(bool latex) {
  std::vector<std::string> files = {"report.html", "report.md", "fit.json"};
  for (const std::string& name : AnalysisFigureNames())
    for (std::string& file : FigureFiles(name, latex)) files.push_back(std::move(file));
  if (latex)
    for (std::string& file : LatexFiles()) files.push_back(std::move(file));
  return files;
}

void CreateReportFolder(const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw EnvironmentError(directory + ": cannot create the folder: " + ec.message());
}

void WriteFitReport(const ExperimentAnalysis& a, const std::string& directory) {
  FigurePool figures;
  WriteFitReport(a, directory, &figures);
}

void WriteFitReport(const ExperimentAnalysis& a, const std::string& directory, FigurePool* figures, bool latex) {
  namespace fs = std::filesystem;
  CreateReportFolder(directory);
  for (GnuplotFigure& f : AnalysisFigures(a)) {
    f.pdf = latex;
    figures->Render(std::move(f), directory);
  }
  for (GnuplotFigure& f : VideoTrialFigures(a)) figures->Render(std::move(f), directory);
  // The documents after the figures: report.html embeds the images.
  figures->Wait();
  const Document d = FitDocument(a, true);
  WriteFileAtomically((fs::path(directory) / "fit.json").string(), AnalysisToJson(a).dump(2) + "\n");
  WriteFileAtomically((fs::path(directory) / "report.md").string(), RenderMarkdown(d));
  WriteFileAtomically((fs::path(directory) / "report.html").string(), RenderHtml(d, directory));
  if (latex) WriteLatexFiles(a, directory);
}

}  // namespace uphill
