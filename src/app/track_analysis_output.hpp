// The outputs of a TrackAnalysis (vision/track_analysis.hpp), shared by `uphill analyse-track`,
// `uphill track … --analyse` and the trials' videos of an experiment (video_trials.hpp):
//   TrackAnalysisTable    the events and the fit as a plain-text table, lengths in mm, times in s
//   TrackAnalysisJson     track_analysis.json, format "uphill-track-analysis/1", SI units; keys
//                         documented in data/README.md, "Track analysis output"
//   TrackAnalysisFigures  track_x_vs_t (measured x(t) against the fitted model) and
//                         track_residuals (measured − predicted, mm), drawn by gnuplot
//   WriteTrackAnalysis    all of them into a directory (created if missing), each file atomically
// They join vision's analysis to report's figures (report/video_trials.hpp), so they live in the
// video use cases: vision does not see report.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "report/gnuplot_figure.hpp"
#include "report/video_trials.hpp"
#include "vision/track_analysis.hpp"

namespace uphill {

std::string TrackAnalysisTable(const TrackAnalysis& analysis);
nlohmann::json TrackAnalysisJson(const TrackAnalysis& analysis);
std::vector<GnuplotFigure> TrackAnalysisFigures(const TrackAnalysis& analysis);
// The figures' data (report/video_trials.hpp draws them, for analyse-track and the fit report).
TrackFigureData TrackFigureDataOf(const TrackAnalysis& analysis);
// Writes DIR/track_analysis.json and the figures (.dat, .gp, .svg, .png). Throws
// EnvironmentError when a file cannot be written or gnuplot fails.
void WriteTrackAnalysis(const TrackAnalysis& analysis, const std::string& directory);
// The names of every file WriteTrackAnalysis may write into its folder.
std::vector<std::string> TrackAnalysisFiles();

}  // namespace uphill
