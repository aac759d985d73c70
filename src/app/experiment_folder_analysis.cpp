#include "app/experiment_folder_analysis.hpp"

#include "model/input_ranges.hpp"
#include "report/figure_pool.hpp"
#include "report/fit_document.hpp"
#include "report/report_outputs.hpp"
#include "report/video_report.hpp"

namespace uphill {

ExperimentFolderAnalysis AnalyseExperimentFolder(const std::string& directory, const ExperimentFolderOptions& options,
                                                 const VideoProgressCallback& progress) {
  return AnalyseLoadedExperiment(LoadExperiment(directory), options, progress);
}

ExperimentFolderAnalysis AnalyseLoadedExperiment(Experiment experiment, const ExperimentFolderOptions& options,
                                                 const VideoProgressCallback& progress) {
  RequireMonteCarloTrials("mc_trials", static_cast<double>(options.analysis.mc_trials));
  ExperimentFolderAnalysis out;
  out.experiment = std::make_shared<Experiment>(std::move(experiment));
  if (!out.experiment->HasVideos()) {
    out.analysis = AnalyseExperiment(*out.experiment, options.analysis);
    return out;
  }
  if (options.one_decode_thread_per_video) OneDecodeThreadPerVideo();
  const std::vector<VideoTrial> trials =
      TrackExperimentVideos(*out.experiment, options.jobs, progress, options.trial_done);
  for (const VideoTrial& t : trials) {
    if (!t.cache_note.empty()) out.notes.push_back(t.cache_note);
    if (!t.error.empty()) out.trial_errors.push_back(t.error);
  }
  out.analysis = AnalyseExperimentWithVideos(out.experiment.get(), trials, options.analysis);
  return out;
}

ExperimentFolderAnalysis WriteExperimentReport(Experiment experiment, const ExperimentReportTarget& target,
                                               const ExperimentFolderOptions& options,
                                               const VideoProgressCallback& progress) {
  CheckReportOutputs(experiment, target.checked.empty() ? target.output : target.checked, target.flag, target.latex);
  FigurePool figures(options.jobs);  // drawing while the videos are tracked, one gnuplot per core
  ExperimentFolderOptions drawing = options;
  drawing.trial_done = [&, folder_made = false](std::size_t index, const VideoTrial& trial) mutable {
    for (GnuplotFigure& figure : VideoTrialFigures(trial, index)) {
      if (!folder_made) CreateReportFolder(target.output);  // not before: a failed report leaves nothing
      folder_made = true;
      figures.Render(std::move(figure), target.output);
    }
    if (options.trial_done) options.trial_done(index, trial);
  };
  ExperimentFolderAnalysis a = AnalyseLoadedExperiment(std::move(experiment), drawing, progress);
  WriteFitReport(a.analysis, target.output, &figures, target.latex);
  return a;
}

}  // namespace uphill
