#include "report/analysis.hpp"

#include <cmath>
#include <cstdio>

#include "fit/least_squares_line.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"
#include "model/propagation.hpp"

namespace uphill {
namespace {

template <typename Fit>
FitOutcome TryFit(const std::string& method, const std::string& title, Fit fit) {
  FitOutcome outcome{method, title, std::nullopt, ""};
  try {
    outcome.report = fit();
  } catch (const InputError& e) {
    outcome.unavailable = e.what();
  }
  return outcome;
}

AnalysedRow AnalyseRow(const ExperimentRow& row, const RowCheck& check, const AnalysisOptions& options) {
  const Configuration& c = *row.configuration;
  const Scene scene = c.MakeScene();
  AnalysedRow r;
  r.source = &row;
  r.theta = scene.rails().theta;
  r.alpha = scene.rails().alpha;
  r.x_max = scene.x_max();
  r.y = row.Y.value;
  r.u_y = row.Y.u;
  if (!scene.x_eq()) throw InputError("body", "a double cone has no equilibrium X to fit Y against");
  r.x_eq = *scene.x_eq();
  PropagationOptions p;
  p.trials = options.mc_trials;
  p.seed = options.seed;
  const PropagationResult propagated = Propagate(c.MakeUncertainRails(), c.MakeUncertainBody(), c.rod_radius, p);
  r.u_x_eq = propagated.x_eq->u_first_order;
  r.u_x_eq_mc = options.mc_trials > 0 ? propagated.x_eq->u_monte_carlo : 0.0;
  r.u_disagrees = propagated.x_eq->disagrees;
  // No inf or NaN reaches the report: a setting the model cannot answer for is this row's error.
  for (const double v : {r.x_eq, r.u_x_eq, r.u_x_eq_mc, r.x_max, r.theta, r.alpha})
    if (!std::isfinite(v))
      throw InputError("the setting", "the model's X or its uncertainty is not a finite number for these values");
  r.flags = check.flags;
  if (r.u_disagrees) r.flags.push_back(UncertaintyDisagreement());
  return r;
}

}  // namespace

const FitOutcome* ExperimentAnalysis::Fit(const std::string& method) const {
  for (const auto& f : fits)
    if (f.method == method) return &f;
  return nullptr;
}

ExperimentAnalysis AnalyseExperiment(const Experiment& experiment, const AnalysisOptions& options) {
  ExperimentAnalysis a;
  a.experiment = &experiment;
  a.row_errors = experiment.Errors();
  const std::vector<RowCheck> checks = CheckRows(experiment);
  for (const ExperimentRow* row : experiment.UsableRows()) {
    try {
      AnalysedRow analysed = AnalyseRow(*row, checks[static_cast<std::size_t>(row - experiment.rows.data())], options);
      (row->excluded.empty() ? a.rows : a.excluded_rows).push_back(std::move(analysed));
    } catch (const InputError& e) {
      a.row_errors.push_back(experiment.directory + "/measurements.csv, row " + std::to_string(row->row) +
                             ": " + e.what());
    }
  }
  if (a.rows.empty() && a.excluded_rows.empty()) {
    // Say what is broken, not only how often: the first row's error names the file, row, column
    // and rule (often one cause for all, e.g. a dimension in experiment.json without its unit).
    if (a.row_errors.empty()) throw InputError(experiment.directory, "has no rows in measurements.csv to analyse");
    const std::size_t n = a.row_errors.size();
    throw InputError(experiment.directory, "no usable rows to analyse: " +
                                               (n == 1 ? std::string("its one row has an error: ")
                                                       : "all " + std::to_string(n) + " rows have errors; the first: ") +
                                               a.row_errors.front());
  }
  LineData line;
  FrictionData friction;
  bool all_u_y = true, all_u_x = true;
  for (const AnalysedRow& r : a.rows) {
    line.x.push_back(r.x_eq);
    line.y.push_back(r.y);
    line.u_x.push_back(r.u_x_eq);
    line.u_y.push_back(r.u_y);
    all_u_y &= r.u_y > 0;
    all_u_x &= r.u_x_eq > 0;
    friction.scenes.push_back(r.source->configuration->MakeScene());
    friction.y.push_back(r.y);
    friction.u_y.push_back(r.u_y);
    // The model value's own uncertainty, from the inputs' (u(X) approximates u(x_rest(mu)):
    // fit/friction_fit.hpp); without it the friction fit's chi2/nu carries the inputs' scatter.
    friction.u_model.push_back(r.u_x_eq);
  }
  if (!all_u_y) {
    friction.u_y.clear();
    friction.u_model.clear();  // the effective variance needs u(Y)
  }
  FitOptions fit_options;
  fit_options.outlier_threshold = options.outlier_threshold;
  a.fits.push_back(TryFit("ols", "Ordinary least squares (the paper's fit)",
                          [&] { return FitOrdinaryLeastSquares(line, fit_options); }));
  a.fits.push_back(TryFit("wls", "Weighted least squares with u(Y)",
                          [&] { return FitWeightedLeastSquares(line, fit_options); }));
  a.fits.push_back(TryFit("york", "Errors in both variables (York 2004), u(X) and u(Y)",
                          [&] { return FitErrorsInVariables(line, fit_options); }));
  RobustOptions robust;
  robust.fit = fit_options;
  a.fits.push_back(TryFit("robust", "Robust straight line (Huber loss)", [&] { return FitRobust(line, robust); }));
  FrictionOptions friction_options;
  friction_options.fit = fit_options;
  try {
    const FrictionVersusLine both = CompareFrictionWithLine(friction, friction_options);
    a.fits.push_back(FitOutcome{"friction", "Rolling-resistance (friction) model Y = x_rest(μ)", both.friction, ""});
    a.friction_vs_line = both.comparison;
  } catch (const InputError& e) {
    a.fits.push_back(FitOutcome{"friction", "Rolling-resistance (friction) model Y = x_rest(μ)", std::nullopt, e.what()});
  }
  if (a.rows.empty())
    a.notes.push_back("Every usable row is excluded from the fit (measurements.csv's excluded column): nothing is fitted.");
  if (!all_u_x) a.notes.push_back("Some rows have u(X) = 0 (no input uncertainties): the York fit needs u(X) > 0.");
  if (a.friction_vs_line) a.notes.push_back(a.friction_vs_line->verdict);
  return a;
}

}  // namespace uphill
