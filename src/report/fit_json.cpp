#include "report/fit_json.hpp"

namespace uphill::report {
namespace {

using nlohmann::ordered_json;

ordered_json Optional(const std::optional<double>& v) { return v ? ordered_json(*v) : ordered_json(nullptr); }

ordered_json Matrix(const Eigen::MatrixXd& m) {
  ordered_json rows = ordered_json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    ordered_json row = ordered_json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

bool IsLine(const FitReport& r) {
  for (const auto& p : r.parameters)
    if (p.name == "k") return true;
  return false;
}

}  // namespace

ordered_json FitToJson(const FitReport& r) {
  ordered_json j;
  j["method"] = MethodName(r.method);
  const ErrorScaling primary = r.primary_scaling;
  if (IsLine(r)) {
    j["slope"] = r.slope();
    j["intercept"] = r.intercept();
    j["u_slope"] = Optional(r.StandardError("k", primary));
    j["u_intercept"] = Optional(r.StandardError("c", primary));
  }
  j["chi2"] = r.chi2;
  j["dof"] = r.dof;
  j["p_value"] = Optional(r.p_value);
  j["n"] = r.n;
  j["standard_errors"] = primary == ErrorScaling::kScaled ? "scaled by sqrt(chi2/dof)" : "unscaled (from the stated uncertainties)";
  ordered_json params = ordered_json::array();
  for (const auto& p : r.parameters)
    params.push_back({{"name", p.name}, {"value", p.value}, {"se_unscaled", p.se_unscaled},
                      {"se_scaled", Optional(p.se_scaled)}});
  j["parameters"] = params;
  j["covariance"] = Matrix(r.covariance);
  j["covariance_scaled"] = r.covariance_scaled ? Matrix(*r.covariance_scaled) : ordered_json(nullptr);
  j["correlation"] = Matrix(r.correlation);
  j["reduced_chi2"] = Optional(r.reduced_chi2);
  j["r_squared"] = Optional(r.r_squared);
  j["aic"] = Optional(r.aic);
  j["bic"] = Optional(r.bic);
  j["exact"] = r.exact;
  j["outlier_threshold"] = r.outlier_threshold;
  ordered_json rows = ordered_json::array();
  for (const auto& row : r.rows)
    rows.push_back({{"row", row.row}, {"fitted", row.fitted}, {"residual", row.residual}, {"sigma", row.sigma},
                    {"normalised_residual", row.normalised}, {"weight", row.weight}, {"outlier", row.outlier}});
  j["rows"] = rows;
  j["outliers"] = r.outliers;
  ordered_json down = ordered_json::array();
  for (const auto& d : r.downweighted)
    down.push_back({{"row", d.row}, {"weight", d.weight}, {"normalised_residual", d.normalised}});
  j["downweighted"] = down;
  j["notes"] = r.notes;
  j["solver"] = {{"converged", r.solver.converged}, {"iterations", r.solver.iterations},
                 {"termination", r.solver.termination}, {"seconds", r.solver.seconds}};
  return j;
}

ordered_json AnalysisToJson(const ExperimentAnalysis& a) {
  ordered_json j;
  j["format"] = kFitJsonFormat;
  const io::Experiment& e = *a.experiment;
  j["experiment"] = {{"directory", e.directory}, {"title", e.title}, {"operator", e.operator_name},
                     {"date", e.date}, {"notes", e.notes}, {"metadata", e.metadata}};
  ordered_json rows = ordered_json::array();
  for (size_t i = 0; i < a.rows.size(); ++i) {
    const AnalysedRow& r = a.rows[i];
    ordered_json row = {{"trial", r.source->trial}, {"series", r.source->series}, {"csv_row", r.source->row},
                        {"theta", r.theta}, {"alpha", r.alpha}, {"x_eq", r.x_eq}, {"u_x_eq", r.u_x_eq},
                        {"u_mc_x_eq", r.u_x_eq_mc}, {"x_max", r.x_max}, {"y", r.y}, {"u_y", r.u_y},
                        {"flags", r.flags}};
    ordered_json residuals = ordered_json::object();
    for (const FitOutcome& f : a.fits)
      if (f.report && i < f.report->rows.size())
        residuals[f.method] = {{"residual", f.report->rows[i].residual},
                               {"normalised", f.report->rows[i].normalised},
                               {"outlier", f.report->rows[i].outlier}};
    row["residuals"] = residuals;
    rows.push_back(row);
  }
  j["rows"] = rows;
  j["row_errors"] = a.row_errors;
  ordered_json fits = ordered_json::object();
  for (const FitOutcome& f : a.fits) {
    ordered_json fit = f.report ? FitToJson(*f.report) : ordered_json{{"method", f.method}};
    fit["title"] = f.title;
    if (!f.report) fit["unavailable"] = f.unavailable;
    fits[f.method] = fit;
  }
  j["fits"] = fits;
  if (a.friction_vs_line) {
    const ModelComparison& c = *a.friction_vs_line;
    j["friction_vs_line"] = {{"first", c.first}, {"second", c.second}, {"delta_chi2", c.delta_chi2},
                             {"delta_aic", c.delta_aic}, {"delta_bic", c.delta_bic},
                             {"akaike_weight_second", c.akaike_weight_second}, {"verdict", c.verdict}};
  }
  j["notes"] = a.notes;
  return j;
}

}  // namespace uphill::report
