#include "report/fit_json.hpp"
#include "report/report_summary.hpp"
#include "report/video_report.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "fit/line_rows.hpp"

namespace uphill {
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

namespace {

// FitToJson's object; with_rows = false leaves "rows" an empty array (WriteFitJson streams them).
ordered_json FitJson(const FitReport& r, bool with_rows) {
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
  if (with_rows)
    for (const RowResult& row : r.rows)
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

}  // namespace

ordered_json FitToJson(const FitReport& r) { return FitJson(r, true); }

namespace {

// A double as nlohmann::json prints it: shortest round-trip digits, ".0" on integral values.
char* Number(char* at, double v) {
  if (!std::isfinite(v)) {
    std::memcpy(at, "null", 4);
    return at + 4;
  }
  char* end = std::to_chars(at, at + 32, v).ptr;
  bool plain_integer = true;
  for (const char* p = at; p < end; ++p) plain_integer &= (*p >= '0' && *p <= '9') || *p == '-';
  if (plain_integer) *end++ = '.', *end++ = '0';
  return end;
}

char* Text(char* at, const char* text) {
  const std::size_t n = std::strlen(text);
  std::memcpy(at, text, n);
  return at + n;
}

// {"row":i,"fitted":…,"residual":…,"sigma":…,"normalised_residual":…,"weight":…,"outlier":…}
char* RowObject(char* at, const RowResult& row) {
  at = Text(at, "{\"row\":");
  at = std::to_chars(at, at + 24, row.row).ptr;
  at = Number(Text(at, ",\"fitted\":"), row.fitted);
  at = Number(Text(at, ",\"residual\":"), row.residual);
  at = Number(Text(at, ",\"sigma\":"), row.sigma);
  at = Number(Text(at, ",\"normalised_residual\":"), row.normalised);
  at = Number(Text(at, ",\"weight\":"), row.weight);
  return Text(at, row.outlier ? ",\"outlier\":true}" : ",\"outlier\":false}");
}

}  // namespace

void WriteFitJson(std::ostream& out, const FitReport& r, const LineData& data, bool with_rows) {
  const ordered_json whole = FitJson(r, false);
  ordered_json head = ordered_json::object(), tail = ordered_json::object();
  bool before = true;
  for (const auto& [key, value] : whole.items()) {
    if (key == "rows") {
      before = false;
      continue;
    }
    (before ? head : tail)[key] = value;
  }
  std::string text = head.dump(2);
  text.resize(text.size() - 2);  // the closing "\n}"
  out << text << ",\n  \"rows\": [";
  // Rows from the report when it kept them, else computed on demand; written in blocks.
  const std::size_t n = !r.rows.empty() ? r.rows.size() : (with_rows && r.row_model.valid ? data.size() : 0);
  std::optional<LineRowResults> on_demand;
  if (r.rows.empty() && n > 0) on_demand.emplace(r, data);
  std::string block;
  constexpr std::size_t kBlock = 1 << 16;
  block.reserve(kBlock + 512);
  char row_text[512];
  for (std::size_t i = 0; i < (with_rows ? n : 0); ++i) {
    block += i ? ",\n    " : "\n    ";
    const RowResult row = on_demand ? (*on_demand)[i] : r.rows[i];
    block.append(row_text, RowObject(row_text, row));
    if (block.size() >= kBlock) {
      out.write(block.data(), static_cast<std::streamsize>(block.size()));
      block.clear();
    }
  }
  out.write(block.data(), static_cast<std::streamsize>(block.size()));
  out << (with_rows && n > 0 ? "\n  ]," : "],");
  const std::string rest = tail.dump(2);
  out << rest.substr(1) << "\n";  // tail's keys after its "{"
}

ordered_json AnalysisToJson(const ExperimentAnalysis& a) {
  ordered_json j;
  j["format"] = kFitJsonFormat;
  const Experiment& e = *a.experiment;
  j["experiment"] = {{"directory", e.directory}, {"title", e.title}, {"operator", e.operator_name},
                     {"date", e.date}, {"notes", e.notes}, {"metadata", e.metadata}};
  const auto row_json = [](const AnalysedRow& r) {
    return ordered_json{{"trial", r.source->trial}, {"series", r.source->series}, {"csv_row", r.source->row},
                        {"theta", r.theta}, {"alpha", r.alpha}, {"x_eq", r.x_eq}, {"u_x_eq", r.u_x_eq},
                        {"u_mc_x_eq", r.u_x_eq_mc}, {"x_max", r.x_max}, {"y", r.y}, {"u_y", r.u_y},
                        {"flags", FlagsJson(r.flags)}};
  };
  ordered_json rows = ordered_json::array();
  for (size_t i = 0; i < a.rows.size(); ++i) {
    ordered_json row = row_json(a.rows[i]);
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
  ordered_json excluded = ordered_json::array();
  for (const AnalysedRow& r : a.excluded_rows) {
    ordered_json row = row_json(r);
    row["excluded"] = r.source->excluded;
    excluded.push_back(row);
  }
  j["excluded_rows"] = excluded;
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
  const ReportSummary summary = SummariseAnalysis(a);
  j["summary"] = {{"preferred", summary.preferred}, {"quote", summary.quote}, {"why", summary.why},
                  {"flagged", summary.flagged}, {"excluded", summary.excluded}};
  AddVideoJson(a, &j);
  j["notes"] = a.notes;
  return j;
}

}  // namespace uphill
