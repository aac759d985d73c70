// Analysing an experiment folder, and writing its report: the use cases of `uphill fit EXP` and
// `uphill report EXP` (docs/fit.md), of the page's report (POST /api/report) and of Python's
// uphill.analyse_experiment. The folder is read (io/experiment.hpp); when its rows name videos
// (format uphill-experiment/2) they are tracked and analysed first, `jobs` at a time and cached
// (app/video_trials.hpp), and a row whose Y is empty takes its video's rest position; then the
// analysis and its fits (report/analysis.hpp).
//
// Defaults: app/analysis_defaults.hpp (the Monte Carlo's trials per row and seed).
// Errors: InputError for a folder that cannot be read (LoadExperiment), for mc_trials outside
// model/input_ranges.hpp's range, and when no row is usable. A video that cannot be analysed is
// not an error of the whole: it is named in trial_errors, and its row (when its Y was to come from
// it) in analysis.row_errors; the other trials and rows are analysed.
// Threads: `jobs` videos at once. A program that does nothing else sets
// one_decode_thread_per_video (OneDecodeThreadPerVideo: process-wide, so the server and the Python
// module leave it unset and keep OpenCV's and FFmpeg's own threads). The callbacks are serialised.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "app/analysis_defaults.hpp"
#include "app/video_trials.hpp"
#include "io/experiment.hpp"
#include "report/analysis.hpp"

namespace uphill {

struct ExperimentFolderOptions {
  AnalysisOptions analysis;  // the defaults: app/analysis_defaults.hpp
  unsigned jobs = 0;                   // videos tracked at once; 0: one per core
  VideoTrialDoneCallback trial_done;   // each video trial as soon as it is finished (the report's figures)
  bool one_decode_thread_per_video = false;  // see "Threads" above
};

struct ExperimentFolderAnalysis {
  // The folder as read, with the videos' rest positions filled in as Y; the analysis points into
  // it, so it lives on the heap (its address is stable however the result is moved).
  std::shared_ptr<Experiment> experiment;
  ExperimentAnalysis analysis;
  std::vector<std::string> trial_errors;  // one line per video that could not be analysed
  std::vector<std::string> notes;         // one line per damaged cache entry that was replaced
};

ExperimentFolderAnalysis AnalyseExperimentFolder(const std::string& directory,
                                                 const ExperimentFolderOptions& options = {},
                                                 const VideoProgressCallback& progress = {});

// The same for a folder already read (a front end that checks its outputs against the inputs
// first, or holds an uphill.Experiment): `experiment` is taken by value and kept in the result.
ExperimentFolderAnalysis AnalyseLoadedExperiment(Experiment experiment, const ExperimentFolderOptions& options = {},
                                                 const VideoProgressCallback& progress = {});

// The report of an experiment (report/fit_document.hpp) written into `output`: first the report
// folder `checked` (the folder the files end up in: `output` itself, or the page's report folder
// when `output` is its staging folder) is checked against the experiment's inputs
// (report/report_outputs.hpp: never over an input; InputError naming `flag`); then the folder is
// analysed as AnalyseLoadedExperiment does, each video trial's figures drawn as soon as the trial
// is finished while the others are tracked (one gnuplot per job); then the documents. `output`
// is created only once something is written into it: a report that fails leaves nothing.
// options.trial_done, when set, is called after a trial's figures were submitted.
struct ExperimentReportTarget {
  std::string output;   // where the files are written
  std::string checked;  // the report folder checked against the inputs ("" : output)
  std::string flag;     // names the folder in an error ("-o", "report")
  bool latex = false;   // also the LaTeX tables and the figures as PDF (report/latex_report.hpp)
};
ExperimentFolderAnalysis WriteExperimentReport(Experiment experiment, const ExperimentReportTarget& target,
                                               const ExperimentFolderOptions& options = {},
                                               const VideoProgressCallback& progress = {});

}  // namespace uphill
