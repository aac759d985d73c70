// ExperimentAnalysis: everything `uphill fit` prints and `uphill report` writes, computed once.
//
// For each usable row of an experiment: the rails' angles, the theoretical equilibrium X with its
// standard uncertainty (first order and Monte Carlo, model/propagation.hpp), the measured Y ± u(Y),
// and the row check's flags (row_check.hpp, the same the page shows) with the Monte Carlo's own. Then the fits of Y against X (fit/): ordinary least squares (the
// paper's), weighted least squares with u(Y), errors in both variables (York) with u(X) and u(Y),
// a robust Huber fit, and the physical friction model Y = x_rest(μ) compared with the straight
// line by χ², AIC and BIC. A fit that cannot be made (too few rows, all X equal, missing
// uncertainties) is kept with the reason instead of its report.
//
// Excluded rows (measurements.csv's `excluded` cell, io/experiment.hpp) are analysed like the
// others (θ, α, X ± u(X), the row check's flags) and kept apart in `excluded_rows`; the fits see
// only `rows`, so every fit, comparison and residual is exactly what it would be with the
// excluded rows deleted from the file. A flagged row is never excluded by the analysis: that is
// the technician's decision (the report's summary warns about flagged rows still fitted).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fit/fit_report.hpp"
#include "fit/friction_fit.hpp"
#include "io/experiment.hpp"
#include "report/row_check.hpp"
#include "report/video_trials.hpp"

namespace uphill {

struct AnalysisOptions {
  std::uint64_t mc_trials = 100000;  // per row, for u(X) by Monte Carlo
  std::uint64_t seed = 1;
  double outlier_threshold = 3.0;
};

struct AnalysedRow {
  const ExperimentRow* source = nullptr;
  double theta = 0, alpha = 0;              // rad
  double x_eq = 0, u_x_eq = 0, u_x_eq_mc = 0;  // m; u first order and Monte Carlo
  bool u_disagrees = false;                  // first order and MC differ by > 5 %
  double x_max = 0;                          // m
  double y = 0, u_y = 0;                     // m
  // The row check's warnings (row_check.hpp: y_below_x, x_beyond_crossbar, …), then
  // u_disagrees when the Monte Carlo's u(X) differs from the first order's.
  std::vector<RowFlag> flags;
};

// One fit: its report, or why it could not be made.
struct FitOutcome {
  std::string method;   // "ols", "wls", "york", "robust", "friction"
  std::string title;    // "Ordinary least squares (the paper's fit)" etc.
  std::optional<FitReport> report;
  std::string unavailable;  // non-empty when report is empty
};

struct ExperimentAnalysis {
  const Experiment* experiment = nullptr;
  std::vector<AnalysedRow> rows;            // the usable rows that are fitted, in file order
  std::vector<AnalysedRow> excluded_rows;   // the usable rows left out of the fits (reason: source->excluded)
  std::vector<std::string> row_errors;      // rows left out, with file, row, column, rule
  std::vector<FitOutcome> fits;             // ols, wls, york, robust, friction, in this order
  std::optional<ModelComparison> friction_vs_line;
  std::vector<std::string> notes;           // findings in plain words
  // What the trials' recordings measured (app/video_trials.hpp fills it in; empty without
  // videos), in the order of the rows with a video.
  std::vector<VideoTrial> video_trials;

  const FitOutcome* Fit(const std::string& method) const;
};

// Throws InputError when no row is usable (nothing to analyse). When every usable row is excluded
// the fits are unavailable, each with the reason.
ExperimentAnalysis AnalyseExperiment(const Experiment& experiment, const AnalysisOptions& options = {});

}  // namespace uphill
