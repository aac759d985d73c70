// Rows excluded from the fit, the report's summary, its LaTeX output and the figures' honesty
// (report/analysis.hpp, report_summary.hpp, latex_report.hpp, quoted_value.hpp, video_trials.hpp).
// Truths: deleting a row from measurements.csv (an excluded row must change every fit exactly as
// that does); the μ = 0.05 the sample series 2 was generated with (data/series2-fixed-L's notes,
// tools/make_samples); fit.json's own values (the summary and the LaTeX tables print them, to
// their printed digits); the GUM's rounding rule worked by hand; LaTeX's syntax (balanced braces,
// files that exist) and pdflatex itself where it is installed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "file_test_support.hpp"
#include "io/experiment.hpp"
#include "report/analysis.hpp"
#include "report/fit_document.hpp"
#include "report/fit_json.hpp"
#include "report/latex_report.hpp"
#include "report/quoted_value.hpp"
#include "report/report_summary.hpp"
#include "report/video_trials.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;
const std::string kSample = std::string(UPHILL_SOURCE_DIR) + "/data/series2-fixed-L";

AnalysisOptions Quick() {
  AnalysisOptions o;
  o.mc_trials = 1000;  // u(X) by Monte Carlo only enters a table column; the fits use the first order
  return o;
}

// The sample's measurements.csv with `edit` applied to its lines (line 0: the header), in a folder
// of its own beside a copy of experiment.json.
fs::path SampleWith(const std::string& name, const std::function<void(std::vector<std::string>&)>& edit) {
  const fs::path dir = FreshFolder(name);
  fs::copy_file(kSample + "/experiment.json", dir / "experiment.json");
  std::vector<std::string> lines;
  std::ifstream in(kSample + "/measurements.csv");
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  edit(lines);
  std::ofstream out(dir / "measurements.csv");
  for (const std::string& line : lines) out << line << "\n";
  return dir;
}

// Every line gets an `excluded` cell after `trial`: `reason` (quoted, RFC 4180) for trial
// `trial`, else blank.
void Exclude(std::vector<std::string>& lines, const std::string& trial, const std::string& reason) {
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::size_t comma = lines[i].find(',');
    const std::string label = lines[i].substr(0, comma);
    lines[i].insert(comma, i == 0 ? ",excluded" : "," + std::string(label == trial ? "\"" + reason + "\"" : ""));
  }
}

// s2-5's Y typed in cm (45.24 for 452.4 mm): the slip the exclusion is for.
void CentimetreSlip(std::vector<std::string>& lines) {
  for (std::string& line : lines)
    if (line.rfind("s2-5,", 0) == 0) line = "s2-5,s2,1165.1,130.1,45.24,";
}

TEST(ExcludedRows, ChangeEveryFitExactlyAsDeletingTheRowDoes) {
  const fs::path excluded = SampleWith("excluded", [](auto& lines) {
    CentimetreSlip(lines);
    Exclude(lines, "s2-5", "  Y typed in cm, 50% & more  ");
  });
  const fs::path deleted = SampleWith("deleted", [](auto& lines) {
    std::erase_if(lines, [](const std::string& l) { return l.rfind("s2-5,", 0) == 0; });
  });
  const fs::path kept = SampleWith("kept", CentimetreSlip);
  const Experiment e_excluded = LoadExperiment(excluded.string());
  const Experiment e_deleted = LoadExperiment(deleted.string());
  const Experiment e_kept = LoadExperiment(kept.string());
  const ExperimentAnalysis a = AnalyseExperiment(e_excluded, Quick());
  const ExperimentAnalysis b = AnalyseExperiment(e_deleted, Quick());
  const ExperimentAnalysis c = AnalyseExperiment(e_kept, Quick());

  ASSERT_EQ(a.rows.size(), 23u);
  ASSERT_EQ(a.excluded_rows.size(), 1u);
  EXPECT_EQ(a.excluded_rows[0].source->trial, "s2-5");
  EXPECT_EQ(a.excluded_rows[0].source->excluded, "Y typed in cm, 50% & more");  // trimmed, kept as typed
  EXPECT_TRUE(a.row_errors.empty());
  // Still checked: the row check flags the slip on the excluded row too.
  EXPECT_FALSE(a.excluded_rows[0].flags.empty());
  ASSERT_EQ(a.fits.size(), b.fits.size());
  for (std::size_t i = 0; i < a.fits.size(); ++i) {
    SCOPED_TRACE(a.fits[i].method);
    ASSERT_TRUE(a.fits[i].report && b.fits[i].report);
    const FitReport &x = *a.fits[i].report, &y = *b.fits[i].report;
    ASSERT_EQ(x.parameters.size(), y.parameters.size());
    for (std::size_t p = 0; p < x.parameters.size(); ++p) {
      EXPECT_EQ(x.parameters[p].value, y.parameters[p].value);
      EXPECT_EQ(x.parameters[p].se_unscaled, y.parameters[p].se_unscaled);
    }
    EXPECT_EQ(x.chi2, y.chi2);
    EXPECT_EQ(x.n, 23u);
    // Kept in the fit, the slip moves the line by far more than its standard error.
    if (a.fits[i].method == "ols") {
      const FitReport& with_slip = *c.fits[i].report;
      EXPECT_GT(std::abs(with_slip.slope() - x.slope()), 10 * *x.StandardError("k", x.primary_scaling));
    }
  }
  ASSERT_TRUE(a.friction_vs_line && b.friction_vs_line);
  EXPECT_EQ(a.friction_vs_line->delta_aic, b.friction_vs_line->delta_aic);

  // fit.json lists it apart, with its reason, and no residuals.
  const auto json = AnalysisToJson(a);
  ASSERT_EQ(json.at("excluded_rows").size(), 1u);
  EXPECT_EQ(json.at("excluded_rows")[0].at("excluded"), "Y typed in cm, 50% & more");
  EXPECT_FALSE(json.at("excluded_rows")[0].contains("residuals"));
  EXPECT_EQ(json.at("rows").size(), 23u);

  // The summary lists it with its reason; the HTML escapes the reason.
  const ReportSummary s = SummariseAnalysis(a);
  ASSERT_EQ(s.excluded.size(), 1u);
  EXPECT_EQ(s.excluded[0], "trial s2-5 (row 6): Y typed in cm, 50% & more");
  const std::string html = RenderHtml(FitDocument(a, false), excluded.string());
  EXPECT_NE(html.find("trial s2-5 (row 6): Y typed in cm, 50% &amp; more"), std::string::npos);
  EXPECT_NE(html.find("excluded from the fit: Y typed in cm"), std::string::npos);  // the trials table

  // Kept in, the same slip is a flagged row the summary warns about.
  const ReportSummary warned = SummariseAnalysis(c);
  EXPECT_TRUE(std::any_of(warned.flagged.begin(), warned.flagged.end(),
                          [](const std::string& f) { return f.rfind("trial s2-5 (row 6): ", 0) == 0; }));
  EXPECT_NE(RenderHtml(FitDocument(c, false), kept.string()).find("flagged but still in the fit"), std::string::npos);
  for (const fs::path& d : {excluded, deleted, kept}) fs::remove_all(d);
}

TEST(ExcludedRows, EveryRowExcludedLeavesNothingFittedAndSaysSo) {
  const fs::path dir = SampleWith("all-excluded", [](auto& lines) {
    lines[0].insert(lines[0].find(','), ",excluded");
    for (std::size_t i = 1; i < lines.size(); ++i) lines[i].insert(lines[i].find(','), ",bad day");
  });
  const Experiment e = LoadExperiment(dir.string());
  const ExperimentAnalysis a = AnalyseExperiment(e, Quick());
  EXPECT_TRUE(a.rows.empty());
  EXPECT_EQ(a.excluded_rows.size(), 24u);
  for (const FitOutcome& f : a.fits) EXPECT_FALSE(f.report) << f.method;
  const ReportSummary s = SummariseAnalysis(a);
  EXPECT_TRUE(s.quote.empty());
  EXPECT_EQ(s.why, "Nothing is fitted: every usable row is excluded from the fit.");
  fs::remove_all(dir);
}

// The sample was generated with μ = 0.05: the friction model is the one to quote, and the quoted
// number is fit.json's μ and its standard error, rounded to two significant digits of the error.
TEST(ReportSummary, TheSampleQuotesTheRollingResistanceCoefficientOfFitJson) {
  const Experiment e = LoadExperiment(kSample);
  const ExperimentAnalysis a = AnalyseExperiment(e, Quick());
  const ReportSummary s = SummariseAnalysis(a);
  EXPECT_EQ(s.preferred, "friction");
  ASSERT_EQ(s.quote.size(), 1u);
  const auto json = AnalysisToJson(a);
  const auto& mu = json.at("fits").at("friction").at("parameters")[0];
  ASSERT_EQ(mu.at("name"), "mu");
  const double value = mu.at("value"), se = mu.at("se_unscaled");  // friction with u(Y): unscaled is primary
  EXPECT_NEAR(value, 0.05, 3 * se);                                 // the generating μ
  std::smatch m;
  ASSERT_TRUE(std::regex_search(s.quote[0], m, std::regex("rolling-resistance coefficient μ = ([0-9.]+) ± ([0-9.]+)")))
      << s.quote[0];
  const std::string printed_value = m[1], printed_u = m[2];
  const int decimals = static_cast<int>(printed_value.size() - printed_value.find('.') - 1);
  const double last_digit = std::pow(10.0, -decimals);
  EXPECT_LE(std::abs(std::stod(printed_value) - value), 0.5 * last_digit + 1e-15);
  EXPECT_LE(std::abs(std::stod(printed_u) - se), 0.5 * last_digit + 1e-15);
  // Two significant digits of the uncertainty.
  EXPECT_GE(std::stod(printed_u) / last_digit, 10.0 - 1e-9);
  EXPECT_LT(std::stod(printed_u) / last_digit, 100.0);
  EXPECT_NE(s.why.find("Both AIC and BIC prefer the friction model"), std::string::npos) << s.why;
  // The HTML report opens with it, in these words.
  const std::string html = RenderHtml(FitDocument(a, false), kSample);
  const std::size_t summary = html.find("<h2>Summary</h2>");
  ASSERT_NE(summary, std::string::npos);
  EXPECT_LT(summary, html.find("<h2>Setup</h2>"));
  EXPECT_NE(html.find("<p>Quote: rolling-resistance coefficient μ = " + printed_value + " ± " + printed_u), std::string::npos);
  EXPECT_NE(html.find("θ (°)"), std::string::npos);
  EXPECT_NE(html.find("χ²/ν"), std::string::npos);
  EXPECT_EQ(html.find("chi2"), std::string::npos);
  EXPECT_EQ(json.at("summary").at("quote")[0], s.quote[0]);
}

TEST(QuotedValue, RoundsTheUncertaintyToTwoDigitsAndTheValueToItsLastDigit) {
  // By hand: u = 0.0012345 has its first digit at 10^-3, so two digits end at 10^-4.
  QuotedValue q = QuoteValue(0.050312, 0.0012345);
  EXPECT_EQ(q.value, "0.0503");
  EXPECT_EQ(q.uncertainty, "0.0012");
  EXPECT_EQ(q.concise, "0.0503(12)");
  EXPECT_EQ(q.PlusMinus(), "0.0503 ± 0.0012");
  q = QuoteValue(-12.3456, 0.87);
  EXPECT_EQ(q.concise, "-12.35(87)");
  q = QuoteValue(123.4, 15.6);
  EXPECT_EQ(q.concise, "123(16)");
  // 0.0996 rounds to 0.10 at two digits: one decimal place fewer, not "0.100".
  q = QuoteValue(1.23456, 0.0996);
  EXPECT_EQ(q.value, "1.23");
  EXPECT_EQ(q.uncertainty, "0.10");
  EXPECT_EQ(q.concise, "1.23(10)");
  q = QuoteValue(-0.00001, 0.0012);
  EXPECT_EQ(q.value, "0.0000");  // no "-0.0000"
  q = QuoteValue(1.2345, 0.0);
  EXPECT_EQ(q.PlusMinus(), "1.2345");
  EXPECT_EQ(q.concise, "1.2345");
}

// Braces balance (a backslash-escaped brace excepted) and close in order.
bool BalancedBraces(const std::string& tex) {
  int depth = 0;
  for (std::size_t i = 0; i < tex.size(); ++i) {
    if (tex[i] == '%' && (i == 0 || tex[i - 1] != '\\')) {  // a comment runs to the line's end
      i = tex.find('\n', i);
      if (i == std::string::npos) break;
      continue;
    }
    if (i > 0 && tex[i - 1] == '\\') continue;
    if (tex[i] == '{') ++depth;
    if (tex[i] == '}' && --depth < 0) return false;
  }
  return depth == 0;
}

TEST(LatexReport, FilesAreWholeIncludableAndPrintFitJsonsNumbers) {
  const fs::path dir = SampleWith("latex", [](auto& lines) { Exclude(lines, "s2-7", "t_7 bumped ~ 2 mm {sic}"); });
  const Experiment e = LoadExperiment(dir.string());
  const ExperimentAnalysis a = AnalyseExperiment(e, Quick());
  const fs::path out = dir / "out";
  CreateReportFolder(out.string());
  {
    FigurePool figures;
    WriteFitReport(a, out.string(), &figures, true);
  }
  for (const std::string& file : FitReportFiles(true)) EXPECT_TRUE(fs::is_regular_file(out / file)) << file;
  for (const char* tex : {"fits.tex", "trials.tex", "report-standalone.tex"}) {
    const std::string text = ReadBytes(out / tex);
    EXPECT_TRUE(BalancedBraces(text)) << tex;
    // Every file the document reads is there; every PDF is whole (ISO 32000-1: %PDF- … %%EOF).
    const std::regex include(R"(\\(?:input|includegraphics)(?:\[[^\]]*\])?\{([^}]+)\})");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), include); it != std::sregex_iterator(); ++it) {
      const std::string file = (*it)[1];
      ASSERT_TRUE(fs::is_regular_file(out / file)) << tex << " includes " << file;
      if (file.ends_with(".pdf")) {
        const std::string pdf = ReadBytes(out / file);
        EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u);
        EXPECT_NE(pdf.find("%%EOF", pdf.size() - 8), std::string::npos);
      }
    }
  }
  // The user's text is escaped: the reason prints as typed.
  EXPECT_NE(ReadBytes(out / "trials.tex").find("excluded: t\\_7 bumped \\textasciitilde{} 2 mm \\{sic\\}"), std::string::npos);
  // Each fit's row: every \num{v(u)} equals fit.json's value and standard error to its printed digits.
  const auto json = nlohmann::json::parse(ReadBytes(out / "fit.json"));
  const std::string fits = ReadBytes(out / "fits.tex");
  const std::vector<std::pair<std::string, std::string>> rows = {
      {"Ordinary least squares", "ols"}, {"Weighted least squares", "wls"}, {"York (errors", "york"},
      {"Rolling resistance", "friction"}};
  for (const auto& [label, method] : rows) {
    SCOPED_TRACE(method);
    const std::size_t at = fits.find("\n" + label);
    ASSERT_NE(at, std::string::npos);
    const std::string line = fits.substr(at + 1, fits.find('\n', at + 1) - at - 1);
    const std::regex num(R"(\\num\{(-?[0-9]+)(?:\.([0-9]+))?\(([0-9]+)\)\})");
    std::vector<std::pair<double, double>> printed;  // value, uncertainty
    for (auto it = std::sregex_iterator(line.begin(), line.end(), num); it != std::sregex_iterator(); ++it) {
      const std::string fraction = (*it)[2];
      const double unit = std::pow(10.0, -static_cast<double>(fraction.size()));
      const std::string whole = (*it)[1];
      const double magnitude = std::abs(std::stod(whole)) + (fraction.empty() ? 0.0 : std::stod("0." + fraction));
      printed.emplace_back((whole[0] == '-' ? -1 : 1) * magnitude, std::stod((*it)[3]) * unit);
    }
    const auto& fit = json.at("fits").at(method);
    const bool scaled = fit.at("standard_errors").get<std::string>().starts_with("scaled");
    std::vector<std::pair<double, double>> expected;  // k, c (mm) or mu
    for (const auto& p : fit.at("parameters")) {
      const double scale = p.at("name") == "c" ? 1e3 : 1.0;
      expected.emplace_back(p.at("value").get<double>() * scale,
                            (scaled ? p.at("se_scaled") : p.at("se_unscaled")).get<double>() * scale);
    }
    ASSERT_EQ(printed.size(), expected.size()) << line;
    for (std::size_t i = 0; i < printed.size(); ++i) {
      const double digits = std::pow(10.0, std::floor(std::log10(printed[i].second)) - 1);  // two digits of u
      EXPECT_LE(std::abs(printed[i].first - expected[i].first), 0.5 * digits * 1.0001) << line;
      EXPECT_LE(std::abs(printed[i].second - expected[i].second), 0.5 * digits * 1.0001) << line;
    }
  }
  // Where a TeX engine is installed, the standalone document compiles.
  if (std::system("command -v pdflatex > /dev/null 2>&1") == 0) {
    const std::string command = "cd '" + out.string() + "' && pdflatex -interaction=nonstopmode -halt-on-error "
                                "report-standalone.tex > latex.log 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << ReadBytes(out / "latex.log");
  }
  fs::remove_all(dir);
}

// A ball at rest: its x(t) figure draws no model line and says so, and its axis spans a few mm
// centred on the positions, not the tracker's hundredths of a millimetre.
TEST(TrackFigures, ABallAtRestIsDrawnAsRestAndPromisesNoLine) {
  TrackFigureData rest;
  for (int i = 0; i < 50; ++i) rest.measured.emplace_back(0.04 * i, 0.30000 + (i % 2 ? 1e-5 : -1e-5));
  const std::vector<GnuplotFigure> figures = TrackFigures(rest, "video_01");
  ASSERT_EQ(figures.size(), 1u);  // no fit: no residuals figure
  const GnuplotFigure& x = figures[0];
  EXPECT_EQ(x.caption.find("the line is"), std::string::npos) << x.caption;
  EXPECT_NE(x.caption.find("no model line"), std::string::npos) << x.caption;
  EXPECT_EQ(x.plot.find("fitted model"), std::string::npos);
  EXPECT_EQ(x.title.find("fitted model"), std::string::npos) << x.title;
  EXPECT_NE(x.plot.find("set yrange [297.5:302.5]"), std::string::npos) << x.plot;
  // A motion over tens of millimetres keeps gnuplot's own range.
  TrackFigureData moving = rest;
  moving.measured.emplace_back(2.0, 0.35);
  EXPECT_EQ(TrackFigures(moving, "video_02")[0].plot.find("set yrange"), std::string::npos);
}

}  // namespace
}  // namespace uphill::testing
