#include "app/experiment_folder_analysis.hpp"

#include "model/input_ranges.hpp"

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
  OneDecodeThreadPerVideo();
  const std::vector<VideoTrial> trials =
      TrackExperimentVideos(*out.experiment, options.jobs, progress, options.trial_done);
  for (const VideoTrial& t : trials) {
    if (!t.cache_note.empty()) out.notes.push_back(t.cache_note);
    if (!t.error.empty()) out.trial_errors.push_back(t.error);
  }
  out.analysis = AnalyseExperimentWithVideos(out.experiment.get(), trials, options.analysis);
  return out;
}

}  // namespace uphill
