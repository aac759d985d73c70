// `uphill fit`: fits of measured Y against theoretical X.
//   uphill fit EXP [--json]                       an experiment folder (data/README.md)
//   uphill fit --xy FILE.csv [--method M] [--json]  arbitrary X-Y data, header X,Y[,uX,uY]
// `uphill report EXP -o DIR [--latex]`: the full report (HTML, Markdown, fit.json, figures; with
// --latex also LaTeX tables and PDF figures, report/latex_report.hpp).
// The work is the app's: FitXy (app/fit_xy.hpp) for --xy data, AnalyseExperimentFolder
// (app/experiment_folder_analysis.hpp) for a folder, which tracks its videos when it has any
// (OpenCV). So an experiment is always analysed in `uphill-vision` (vision_program.hpp): one path
// for folders with and without videos.
#include <unistd.h>

#include <optional>
#include <iostream>

#include "app/analysis_defaults.hpp"
#include "app/fit_xy.hpp"
#include "commands.hpp"
#include "flag_checks.hpp"
#include "io/xy_table.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "report/fit_document.hpp"
#include "report/fit_json.hpp"
#include "report/fit_text.hpp"
#include "vision_program.hpp"
#if UPHILL_VISION_PROGRAM
#include "app/experiment_folder_analysis.hpp"
#include "video_progress.hpp"
#endif

namespace uphill::cli {
namespace {

struct FitFlags {
  std::string experiment;
  std::string xy;
  std::string method = kDefaultFitXyMethod;
  bool json = false;
  bool no_rows = false;
  std::int64_t mc_trials = kAnalysisMonteCarloTrials;  // signed: "-1" is refused as -1, not wrapped
  const CLI::App* command = nullptr;  // to ask which flags were given
  std::string output;
  unsigned jobs = 0;  // videos tracked at once; 0: one per core
  bool quiet = false;
  bool latex = false;  // report: also fits.tex, trials.tex, the figures as PDF, report-standalone.tex
};


void RunXy(const FitFlags& f) {
  const FitMethod method = ParseFitMethod(f.method, "--method");  // before the file is read
  // X,Y[,uX,uY] (io/xy_table.hpp): a row that cannot be read is named on stderr as it is met and
  // left out; the fit uses the others (exit status 2 tells).
  XyTable table = ReadXyFile(f.xy, [](const std::string& error) {
    std::cerr << "uphill: " << error << " (row left out)\n";
    ExitStatus() = 2;
  });
  const LineData data{std::move(table.x), std::move(table.y), std::move(table.u_x), std::move(table.u_y)};
  FitReport r;
  try {
    FitXyOptions options;
    options.fit.keep_rows = false;  // the JSON output streams the rows from the data (line_rows.hpp)
    r = FitXy(method, data, options);
  } catch (const InputError& e) {
    throw InputError(table.Locate(e.quantity()), e.rule());  // name the file's row and column
  }
  if (f.json) {
    WriteFitJson(std::cout, r, data, !f.no_rows);
  } else {
    std::cout << FitReportText(r);
  }
}

#if UPHILL_VISION_PROGRAM

// `output`, when given (`uphill report`): the report is written there, each video trial's
// figures as soon as the trial is tracked.
ExperimentFolderAnalysis Analyse(const FitFlags& f, Experiment experiment, const std::string& output = "") {
  RequireMonteCarloTrials("--mc-trials", static_cast<double>(f.mc_trials));
  ExperimentFolderOptions options;
  options.analysis.mc_trials = static_cast<std::uint64_t>(f.mc_trials);
  options.jobs = f.jobs;
  options.one_decode_thread_per_video = true;  // this process only tracks: the cores go across videos
  std::vector<std::string> labels;
  for (const ExperimentRow* r : VideoRows(experiment)) labels.push_back(r->trial + "  " + r->video);
  std::optional<VideoProgressDisplay> display;
  if (!f.quiet && isatty(STDERR_FILENO) && !labels.empty()) display.emplace(labels);
  const auto progress = [&](const VideoProgress& p) { if (display) display->Update(p); };
  ExperimentFolderAnalysis a = output.empty()
                                   ? AnalyseLoadedExperiment(std::move(experiment), options, progress)
                                   : WriteExperimentReport(std::move(experiment), {output, "", "-o", f.latex}, options,
                                                           progress);
  if (display) display->Finish();
  for (const std::string& note : a.notes) std::cerr << "uphill: note: " << note << "\n";
  for (const std::string& e : a.trial_errors) std::cerr << "uphill: " << e << " (video left out)\n";
  for (const std::string& e : a.analysis.row_errors) std::cerr << "uphill: " << e << " (row left out)\n";
  if (!a.trial_errors.empty() || !a.analysis.row_errors.empty()) ExitStatus() = 2;
  return a;
}

void RunExperiment(const FitFlags& f) {
  const ExperimentFolderAnalysis a = Analyse(f, LoadExperiment(f.experiment));
  if (f.json) {
    std::cout << AnalysisToJson(a.analysis).dump(2) << "\n";
  } else {
    std::cout << RenderText(FitDocument(a.analysis, false));
  }
}

void RunReport(const FitFlags& f) {
  const ExperimentFolderAnalysis a = Analyse(f, LoadExperiment(f.experiment), f.output);
  std::cout << "wrote " << f.output << "/report.html, report.md, fit.json, and the figures "
            << "fit_y_vs_x, fit_offset, fit_residuals";
  if (!a.analysis.video_trials.empty()) std::cout << ", and each video's video_<n>_x_vs_t, video_<n>_residuals";
  std::cout << " (.svg, .png, .gp script, .dat data)\n";
  if (f.latex)
    std::cout << "wrote " << f.output << "/fits.tex, trials.tex, report-standalone.tex and the figures as .pdf "
              << "(\\input and \\includegraphics them; pdflatex report-standalone.tex in the folder)\n";
}

#else  // uphill: an experiment is analysed in uphill-vision, which tracks its videos (OpenCV)

void RunExperiment(const FitFlags&) { RunInVisionProgram(); }
void RunReport(const FitFlags&) { RunInVisionProgram(); }

#endif

void AddVideoFlags(CLI::App* command, FitFlags* flags) {
  command->add_option("--jobs", flags->jobs, "videos tracked at once (experiment with recordings; 0: one per core)")
      ->capture_default_str();
  command->add_flag("--quiet", flags->quiet, "no progress bars while the videos are tracked");
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  auto flags = std::make_shared<FitFlags>();
  CLI::App* fit = app.add_subcommand("fit", "Fit measured Y against theoretical X (experiment folder or X-Y CSV)");
  fit->add_option("experiment", flags->experiment, "experiment folder (experiment.json + measurements.csv)");
  fit->add_option("--xy", flags->xy, "CSV with header X,Y and optionally uX,uY (plain numbers, same units)");
  fit->add_option("--method", flags->method, "with --xy: ols | wls | york | robust")->capture_default_str();
  fit->add_flag("--json", flags->json, "JSON output (stable keys: docs/fit.md)");
  fit->add_flag("--no-rows", flags->no_rows, "with --xy --json: leave the per-row entries out (\"rows\": [])");
  fit->add_option("--mc-trials", flags->mc_trials, "Monte Carlo trials per row for u(X)")->capture_default_str();
  AddVideoFlags(fit, flags.get());
  fit->callback([flags, fit] {
    flags->command = fit;
    RefuseEmpty(fit, "--xy", flags->xy, "a CSV file, or - for stdin");
    if (flags->xy.empty() == flags->experiment.empty())
      throw InputError("fit", "give either an experiment folder or --xy FILE.csv");
    RefuseIgnored(fit, "--method", flags->xy.empty(), "applies to --xy data only (an experiment gets every fit)");
    RefuseIgnored(fit, "--mc-trials", !flags->xy.empty(), "applies to an experiment folder only (--xy data has no X to propagate)");
    RefuseIgnored(fit, "--no-rows", flags->xy.empty() || !flags->json, "applies to --xy with --json only");
    if (!flags->xy.empty()) RunXy(*flags);
    else RunExperiment(*flags);
  });

  CLI::App* report = app.add_subcommand("report", "Write the fit report of an experiment (HTML, Markdown, JSON, figures)");
  report->add_option("experiment", flags->experiment, "experiment folder")->required();
  report->add_option("-o,--output", flags->output, "output folder (created if needed)")->required();
  report->add_option("--mc-trials", flags->mc_trials, "Monte Carlo trials per row for u(X)")->capture_default_str();
  report->add_flag("--latex", flags->latex,
                    "also write LaTeX: fits.tex, trials.tex (siunitx), the figures as PDF, report-standalone.tex");
  AddVideoFlags(report, flags.get());
  report->callback([flags] { RunReport(*flags); });
}

}  // namespace uphill::cli
