// `uphill fit`: fits of measured Y against theoretical X.
//   uphill fit EXP [--json]                       an experiment folder (data/README.md)
//   uphill fit --xy FILE.csv [--method M] [--json]  arbitrary X-Y data, header X,Y[,uX,uY]
// `uphill report EXP -o DIR`: the full report (HTML, Markdown, fit.json, figures).
#include <charconv>
#include <iostream>

#include "commands.hpp"
#include "fit/least_squares_line.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "io/csv_table.hpp"
#include "model/input_error.hpp"
#include "report/fit_document.hpp"
#include "report/fit_json.hpp"

namespace uphill::cli {
namespace {

struct FitFlags {
  std::string experiment;
  std::string xy;
  std::string method = "ols";
  bool json = false;
  std::uint64_t mc_trials = 100000;
  std::string output;
};

double Cell(const io::CsvTable& table, const io::CsvRow& row, int column) {
  const std::string& text = row.cells[column];
  double v = 0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  while (begin < end && *begin == ' ') ++begin;
  if (begin < end && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, v);
  const std::string where = io::CellContext(table, row.row, table.header[column]);
  if (ec != std::errc() || ptr == begin) throw InputError(where, "'" + text + "' is not a number");
  for (const char* p = ptr; p < end; ++p)
    if (*p != ' ') throw InputError(where, "'" + text + "' is not a plain number");
  if (!std::isfinite(v)) throw InputError(where, "'" + text + "' is not a finite number");
  return v;
}

// Reads X,Y[,uX,uY]; rows that cannot be read are reported on stderr and left out.
LineData ReadXy(const std::string& path) {
  const io::CsvTable table = io::ReadCsvFile(path);
  for (const auto& name : table.header)
    if (name != "X" && name != "Y" && name != "uX" && name != "uY")
      throw InputError(io::CellContext(table, 1, name), "unknown column (expected X, Y and optionally uX, uY)");
  const int cx = table.Column("X"), cy = table.Column("Y"), cux = table.Column("uX"), cuy = table.Column("uY");
  if (cx < 0 || cy < 0) throw InputError(table.source + ", row 1", "the header must have columns X and Y");
  LineData data;
  for (const io::CsvRow& row : table.rows) {
    try {
      if (!row.error.empty()) throw InputError(table.source + ", row " + std::to_string(row.row), row.error);
      const double x = Cell(table, row, cx), y = Cell(table, row, cy);
      const double ux = cux >= 0 ? Cell(table, row, cux) : 0.0, uy = cuy >= 0 ? Cell(table, row, cuy) : 0.0;
      data.x.push_back(x);
      data.y.push_back(y);
      if (cux >= 0) data.u_x.push_back(ux);
      if (cuy >= 0) data.u_y.push_back(uy);
    } catch (const InputError& e) {
      std::cerr << "uphill: " << e.what() << " (row left out)\n";
      ExitStatus() = 2;
    }
  }
  return data;
}

void PrintFitText(const FitReport& r) {
  std::cout << "method: " << MethodName(r.method) << ", n = " << r.n << ", dof = " << r.dof << "\n";
  for (const auto& p : r.parameters) {
    std::cout << "  " << p.name << " = " << p.value << "  ± " << p.se_unscaled << " (unscaled)";
    if (p.se_scaled) std::cout << "  ± " << *p.se_scaled << " (scaled by sqrt(chi2/dof))";
    std::cout << "\n";
  }
  std::cout << "  chi2 = " << r.chi2;
  if (r.reduced_chi2) std::cout << ", chi2/dof = " << *r.reduced_chi2;
  if (r.p_value) std::cout << ", p = " << *r.p_value;
  std::cout << "\n";
  for (size_t i : r.outliers) std::cout << "  outlier: row " << i + 1 << " of the data\n";
  for (const auto& d : r.downweighted) std::cout << "  down-weighted: row " << d.row + 1 << " (weight " << d.weight << ")\n";
  for (const auto& n : r.notes) std::cout << "  note: " << n << "\n";
}

void RunXy(const FitFlags& f) {
  const LineData data = ReadXy(f.xy);
  FitReport r;
  if (f.method == "ols") r = FitOrdinaryLeastSquares(data);
  else if (f.method == "wls") r = FitWeightedLeastSquares(data);
  else if (f.method == "york") r = FitErrorsInVariables(data);
  else if (f.method == "robust") r = FitRobust(data);
  else throw InputError("--method", "must be ols, wls, york or robust (got '" + f.method + "')");
  if (f.json) {
    std::cout << report::FitToJson(r).dump(2) << "\n";
  } else {
    PrintFitText(r);
  }
}

report::ExperimentAnalysis Analyse(const FitFlags& f, io::Experiment* keep) {
  *keep = io::LoadExperiment(f.experiment);
  report::AnalysisOptions options;
  options.mc_trials = f.mc_trials;
  report::ExperimentAnalysis a = report::AnalyseExperiment(*keep, options);
  for (const auto& e : a.row_errors) {
    std::cerr << "uphill: " << e << " (row left out)\n";
    ExitStatus() = 2;
  }
  return a;
}

void RunExperiment(const FitFlags& f) {
  io::Experiment experiment;
  const report::ExperimentAnalysis a = Analyse(f, &experiment);
  if (f.json) {
    std::cout << report::AnalysisToJson(a).dump(2) << "\n";
  } else {
    std::cout << report::RenderText(report::FitDocument(a, false));
  }
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  auto flags = std::make_shared<FitFlags>();
  CLI::App* fit = app.add_subcommand("fit", "Fit measured Y against theoretical X (experiment folder or X-Y CSV)");
  fit->add_option("experiment", flags->experiment, "experiment folder (experiment.json + measurements.csv)");
  fit->add_option("--xy", flags->xy, "CSV with header X,Y and optionally uX,uY (plain numbers, same units)");
  fit->add_option("--method", flags->method, "with --xy: ols | wls | york | robust")->capture_default_str();
  fit->add_flag("--json", flags->json, "JSON output (see README: stable keys)");
  fit->add_option("--mc-trials", flags->mc_trials, "Monte Carlo trials per row for u(X)")->capture_default_str();
  fit->callback([flags] {
    if (flags->xy.empty() == flags->experiment.empty())
      throw InputError("fit", "give either an experiment folder or --xy FILE.csv");
    if (!flags->xy.empty()) RunXy(*flags);
    else RunExperiment(*flags);
  });

  CLI::App* report = app.add_subcommand("report", "Write the fit report of an experiment (HTML, Markdown, JSON, figures)");
  report->add_option("experiment", flags->experiment, "experiment folder")->required();
  report->add_option("-o,--output", flags->output, "output folder (created if needed)")->required();
  report->add_option("--mc-trials", flags->mc_trials, "Monte Carlo trials per row for u(X)")->capture_default_str();
  report->callback([flags] {
    io::Experiment experiment;
    const report::ExperimentAnalysis a = Analyse(*flags, &experiment);
    report::WriteFitReport(a, flags->output);
    std::cout << "wrote " << flags->output << "/report.html, report.md, fit.json, and the figures "
              << "fit_y_vs_x, fit_offset, fit_residuals (.svg, .png, .gp script, .dat data)\n";
  });
}

}  // namespace uphill::cli
