#include "server/row_check.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "app/fit_xy.hpp"
#include "app/row_check.hpp"
#include "io/configuration.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

FieldSource MakeSource(const ExperimentState& state, const Row& row, const std::vector<std::string>& columns) {
  const json meta = state.metadata.is_object() ? json(state.metadata) : json::object();
  const json body = meta.value("body", json::object());
  const json apparatus = meta.value("apparatus", json::object());
  const json defaults = meta.value("uncertainties", json::object());
  const auto text = [](const json& j) { return j.is_string() ? j.get<std::string>() : j.dump(); };
  FieldSource source;
  source.lookup = [=, &row, &state](const std::string& name) -> std::optional<FieldSource::Field> {
    if (name == "body") return FieldSource::Field{body.contains("type") ? text(body.at("type")) : "", ""};
    if (name == "L_convention")
      return apparatus.contains(name) ? std::optional<FieldSource::Field>({text(apparatus.at(name)), ""})
                                      : std::nullopt;
    if (std::find(columns.begin(), columns.end(), name) != columns.end()) {
      if (!row.Value(name).empty()) return FieldSource::Field{row.Value(name), state.unit};
      if (name.rfind("u_", 0) != 0) return FieldSource::Field{"", ""};  // refused as empty
    }
    if (body.contains(name)) return FieldSource::Field{text(body.at(name)), ""};
    if (apparatus.contains(name)) return FieldSource::Field{text(apparatus.at(name)), ""};
    if (name.rfind("u_", 0) == 0 && defaults.contains(name.substr(2)))
      return FieldSource::Field{text(defaults.at(name.substr(2))), "", true};
    return std::nullopt;
  };
  source.context = [=](const std::string& name) -> std::string {
    if (std::find(columns.begin(), columns.end(), name) != columns.end()) return name;
    if (name == "body") return "experiment.body.type";
    if (body.contains(name)) return "experiment.body." + name;
    if (apparatus.contains(name)) return "experiment.apparatus." + name;
    if (name.rfind("u_", 0) == 0) return "experiment.uncertainties." + name.substr(2);
    return name + " (neither a column nor an apparatus constant)";
  };
  return source;
}

RowCheck Refused(const std::string& message) {
  RowCheck check;
  check.flags.push_back({"invalid", "", message, FlagSeverity::kError});
  return check;
}

json Number(std::optional<double> v) { return v ? json(*v) : json(nullptr); }

}  // namespace

Configuration RowConfiguration(const ExperimentState& state, const Row& row) {
  return ParseConfiguration(MakeSource(state, row, state.Columns()));
}

Experiment StateExperiment(const ExperimentState& state) {
  if (!state.exists || !state.metadata.is_object())
    throw InputError(kExperimentJsonFile, "create the experiment first (body, apparatus, units)");
  ExperimentFolder folder = ParseExperimentJson("", state.ExperimentJson());
  const CsvTable measurements = ParseMeasurements(folder, state.MeasurementsCsv());
  Experiment e = ParseExperiment(std::move(folder), measurements);
  // One record per row: the page's rows have a trial label, so none is a blank line.
  if (e.rows.size() != state.rows.size())
    throw InputError(kMeasurementsCsvFile, "the page's rows did not read back one to one (" +
                                               std::to_string(e.rows.size()) + " of " +
                                               std::to_string(state.rows.size()) + ")");
  return e;
}

RowCheck CheckRow(const ExperimentState& state, const Row& row) {
  ExperimentState with_row = state;
  const int index = row.id != 0 ? state.IndexOf(row.id) : -1;
  if (index >= 0) {
    with_row.rows[static_cast<std::size_t>(index)] = row;
  } else {
    with_row.rows.push_back(row);
  }
  try {
    const Experiment e = StateExperiment(with_row);
    return uphill::CheckRow(e, e.rows[index >= 0 ? static_cast<std::size_t>(index) : e.rows.size() - 1]);
  } catch (const InputError& e) {
    return Refused(e.what());
  }
}

RowCheck CheckDraft(const ExperimentState& state, const Row& row) {
  if (!row.Value("Y").empty() || !row.video.empty()) return CheckRow(state, row);
  // The one check judges whole rows (a row without Y is refused before its model is computed):
  // it sees the draft with a stand-in Y, and everything that Y decides is taken out again.
  Row with_y = row;
  with_y.values["Y"] = "1";
  RowCheck check = CheckRow(state, with_y);
  check.y = check.u_y = std::nullopt;
  std::erase_if(check.flags, [](const RowFlag& f) { return f.field == "Y" || f.code == "duplicate_row"; });
  return check;
}

ordered_json CheckAnswer(const ExperimentState& state, const json& row_json) {
  Row row;
  ordered_json out = {{"complete", true}};
  try {
    row = ValidateRow(row_json, state);
  } catch (const InputError& e) {
    out = {{"complete", false}, {"error", e.what()}, {"field", e.quantity()}};
    try {
      row = ValidateRow(row_json, state, RowStage::kDraft);
    } catch (const InputError&) {
      return out;
    }
  }
  row.id = row_json.is_object() && row_json.contains("id") && row_json.at("id").is_number_integer()
               ? row_json.at("id").get<std::int64_t>()
               : 0;
  const ordered_json check = ToJson(CheckDraft(state, row), state.unit);
  for (const auto& [k, v] : check.items()) out[k] = v;
  return out;
}

ordered_json ToJson(const RowCheck& check, const std::string& unit) { return RowCheckJson(check, unit); }

ordered_json CheckAll(const ExperimentState& state) {
  std::vector<RowCheck> checks;
  if (!state.rows.empty()) try {
      checks = CheckRows(StateExperiment(state));
    } catch (const InputError& e) {
      checks.assign(state.rows.size(), Refused(e.what()));
    }
  const double to_unit = 1.0 / UnitFactor(Dimension::kLength, state.unit);
  ordered_json out;
  out["checks"] = ordered_json::array();
  LineData data;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    const RowCheck& c = checks[i];
    ordered_json j = {{"id", state.rows[i].id}};
    const ordered_json check = ToJson(c, state.unit);
    for (const auto& [k, v] : check.items()) j[k] = v;
    out["checks"].push_back(j);
    if (c.x_eq && c.y && state.rows[i].excluded.empty()) {  // an excluded row is shown, never fitted
      data.x.push_back(*c.x_eq * to_unit);
      data.y.push_back(*c.y * to_unit);
    }
  }
  const auto excluded = std::count_if(state.rows.begin(), state.rows.end(), [](const Row& r) { return !r.excluded.empty(); });
  ordered_json fit = {{"n", data.size()}, {"excluded", excluded}};
  try {
    if (data.size() < 2) throw InputError("fit", "needs at least 2 rows with X and Y");
    const FitReport r = FitXy(FitMethod::kOrdinaryLeastSquares, data);
    fit["slope"] = r.slope();
    fit["intercept"] = r.intercept();
    fit["u_slope"] = Number(r.StandardError("k", ErrorScaling::kScaled));
    fit["u_intercept"] = Number(r.StandardError("c", ErrorScaling::kScaled));
    fit["r_squared"] = Number(r.r_squared);
    fit["residual_sd"] = r.reduced_chi2 ? json(std::sqrt(*r.reduced_chi2)) : json(nullptr);
  } catch (const std::exception& e) {
    fit["unavailable"] = e.what();
  }
  out["fit"] = fit;
  return out;
}

}  // namespace uphill
