// The defaults of an experiment's analysis (app/experiment_folder_analysis.hpp) that every front
// end takes and states: `uphill fit EXP` / `report` (their --help), the page's report and Python's
// uphill.analyse_experiment. Apart from the use case so that `uphill`, which does not link OpenCV,
// can show them.
#pragma once

#include <cstdint>

#include "report/analysis.hpp"

namespace uphill {

// Monte Carlo trials per row for u(X) (model/propagation.hpp): 10^5 give u to about 0.2 %
// (relative standard error of a standard deviation from M draws: 1/sqrt(2M)).
inline constexpr std::uint64_t kAnalysisMonteCarloTrials = 100000;
inline constexpr std::uint64_t kAnalysisSeed = 1;

// The analysis options every front end starts from.
inline AnalysisOptions DefaultAnalysisOptions() {
  AnalysisOptions o;
  o.mc_trials = kAnalysisMonteCarloTrials;
  o.seed = kAnalysisSeed;
  return o;
}

}  // namespace uphill
