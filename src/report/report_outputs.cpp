#include "report/report_outputs.hpp"

#include <filesystem>
#include <vector>

#include "io/output_paths.hpp"
#include "report/fit_document.hpp"
#include "report/gnuplot_figure.hpp"
#include "report/video_report.hpp"

namespace uphill {

void CheckReportOutputs(const Experiment& experiment, const std::string& directory, const std::string& flag,
                        bool latex) {
  namespace fs = std::filesystem;
  const fs::path root(experiment.directory);
  OutputPaths outputs;
  outputs.AddInput((root / kExperimentJsonFile).string(), "the experiment's");
  outputs.AddInput((root / kMeasurementsCsvFile).string(), "the experiment's");
  if (!experiment.camera.empty()) outputs.AddInput((root / experiment.camera).string(), "the experiment's camera file");
  for (const auto& [name, file] : experiment.scenes)
    outputs.AddInput((root / file).string(), "the experiment's scene file '" + name + "'");
  std::vector<std::string> files = FitReportFiles(latex);
  std::size_t video_index = 0;
  for (const ExperimentRow& row : experiment.rows) {
    if (row.video.empty()) continue;
    outputs.AddInput((root / row.video).string(), "the video of trial '" + row.trial + "'");
    if (!row.error.empty()) continue;  // no figures: not tracked
    for (const std::string& figure : VideoTrialFigureNames(video_index++))
      for (std::string& file : FigureFiles(figure)) files.push_back(std::move(file));
  }
  outputs.AddInputFolder((root / kVideoCacheFolder).string(), "the experiment's video cache");
  outputs.CheckFolder(directory, flag, files);
}

}  // namespace uphill
