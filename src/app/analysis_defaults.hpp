// The defaults of an experiment's analysis (app/experiment_folder_analysis.hpp) that every front
// end takes and states: `uphill fit EXP` / `report` (their --help), the page's report and Python's
// uphill.analyse_experiment. They are AnalysisOptions' own (report/analysis.hpp), named here, apart
// from the use case, so that `uphill`, which does not link OpenCV, can show them.
#pragma once

#include <cstdint>

#include "report/analysis.hpp"

namespace uphill {

inline constexpr AnalysisOptions kAnalysisDefaults{};
// Monte Carlo trials per row for u(X) (model/propagation.hpp): 10^5 give u to about 0.2 %
// (relative standard error of a standard deviation from M draws: 1/sqrt(2M)).
inline constexpr std::uint64_t kAnalysisMonteCarloTrials = kAnalysisDefaults.mc_trials;
inline constexpr std::uint64_t kAnalysisSeed = kAnalysisDefaults.seed;
inline constexpr double kAnalysisOutlierThreshold = kAnalysisDefaults.outlier_threshold;

}  // namespace uphill
