// The fit report's part about the trials' recordings (report/video_trials.hpp), added to the
// report of an experiment whose analysis carries video trials (ExperimentAnalysis::video_trials):
//   - "Rest positions from the videos": each video trial's Y (typed, from the video, both with
//     their standard uncertainties, typed − video in σ and a flag beyond 3σ);
//   - "Motion fits": release x0 and t0, μ or g_eff ± its standard error (scaled by sqrt(χ²/ν)),
//     χ²/ν, the events, notes;
//   - "Friction cross-check": μ from the motions (weighted mean) next to μ of the friction fit of
//     the rest positions, their difference in combined σ;
//   - the videos that could not be analysed;
//   - per trial the figures video_<n>_x_vs_t and video_<n>_residuals (n from 1 in the order of the
//     video trials).
// Lengths in mm, times in s; nothing when there are no video trials.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "report/analysis.hpp"
#include "report/document.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill {

void AddVideoSections(const ExperimentAnalysis& analysis, bool with_figures, Document* document);
std::vector<GnuplotFigure> VideoTrialFigures(const ExperimentAnalysis& analysis);
// The figures of one trial, the `index`-th of the video trials (from 0): what
// VideoTrialFigures(analysis) holds for it, so that they can be drawn as soon as it is tracked.
std::vector<GnuplotFigure> VideoTrialFigures(const VideoTrial& trial, std::size_t index);
// The names every figure of the `index`-th video trial may have (x_vs_t, residuals).
std::vector<std::string> VideoTrialFigureNames(std::size_t index);
// fit.json's "video_trials" (VideoTrialToJson without figure data) and "motion_mu".
void AddVideoJson(const ExperimentAnalysis& analysis, nlohmann::ordered_json* j);

}  // namespace uphill
