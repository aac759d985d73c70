#include "server/row_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "fit/least_squares_line.hpp"
#include "io/configuration.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/propagation.hpp"

namespace uphill {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

constexpr double kInch = 0.0254;

struct Range {
  double low, high;
};
// What the apparatus can physically be (SI). Wide on purpose: a flag must mean "look again".
const std::map<std::string, Range> kPlausible = {
    {"L", {0.05, 5.0}}, {"H", {0.0, 2.0}}, {"D", {0.003, 1.0}}, {"Y", {1e-9, 5.0}}};

std::string Format(double v, const std::string& unit) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g %s", ToUnit(v, Dimension::kLength, unit), unit.c_str());
  return buf;
}

// The state's numbers, parsed once per request (CheckAll checks every row against the others).
struct Context {
  const ExperimentState* state = nullptr;
  std::map<std::string, std::vector<double>> sorted;  // quantity -> the rows' SI values, sorted
  std::map<std::string, std::vector<std::int64_t>> by_values;  // "L|H|D|Y" -> row ids
  std::map<std::string, std::vector<std::int64_t>> by_trial;
};

std::optional<double> Si(const Row& row, const std::string& q, const std::string& unit) {
  const std::string& text = row.Value(q);
  if (text.empty()) return std::nullopt;
  try {
    return ParseQuantity(text, Dimension::kLength, q, unit);
  } catch (const InputError&) {
    return std::nullopt;
  }
}

std::string ValuesKey(const Row& row, const ExperimentState& state) {
  std::string key;
  for (const char* q : {"L", "H", "D", "Y"}) {
    const auto v = Si(row, q, state.unit);
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.12g|", v ? *v : -1.0);
    key += buf;
  }
  return key;
}

Context MakeContext(const ExperimentState& state) {
  Context c;
  c.state = &state;
  for (const Row& r : state.rows) {
    for (const char* q : {"L", "H", "D", "Y"})
      if (const auto v = Si(r, q, state.unit)) c.sorted[q].push_back(*v);
    c.by_values[ValuesKey(r, state)].push_back(r.id);
    c.by_trial[r.trial].push_back(r.id);
  }
  for (auto& [q, v] : c.sorted) std::sort(v.begin(), v.end());
  return c;
}

// Median of `sorted` without one instance of `self` (when the row is stored), or of all.
std::optional<double> Median(const std::vector<double>& sorted, std::optional<double> self) {
  const std::size_t n = sorted.size();
  std::size_t skip = n;  // index left out, n = none
  if (self) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), *self);
    if (it != sorted.end() && *it == *self) skip = static_cast<std::size_t>(it - sorted.begin());
  }
  const std::size_t m = skip < n ? n - 1 : n;
  if (m == 0) return std::nullopt;
  const auto at = [&](std::size_t i) { return sorted[i < skip ? i : i + 1]; };
  return m % 2 ? at(m / 2) : 0.5 * (at(m / 2 - 1) + at(m / 2));
}

// "looks like inches/cm" when value/reference is within a factor of the ratio a mix-up gives:
// 1/25.4 (inches in a mm field; a factor 1.6 either way, since settings of one series differ and Y
// lies beyond X), 1/10 (cm in a mm field; a factor 1.45, so the two bands do not overlap), or
// 25.4 (mm in an inch field).
std::optional<std::string> MixUp(double value, double reference, const std::string& unit) {
  if (!(reference > 0) || !(value > 0)) return std::nullopt;
  const double r = value / reference;
  const auto near = [&](double target, double factor) { return std::abs(std::log(r / target)) < std::log(factor); };
  const double per_unit = UnitFactor(Dimension::kLength, unit);
  if (unit != "in" && near(per_unit / kInch, 1.6))
    return "looks like inches typed in a " + unit + " field (as inches: " + Format(value / per_unit * kInch, unit) + ")";
  if (unit == "mm" && near(0.1, 1.45)) return std::string("looks like cm typed in a mm field (×10)");
  if (unit == "in" && near(kInch / 0.001, 1.6)) return std::string("looks like mm typed in an inch field");
  return std::nullopt;
}

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

void Add(RowCheck& check, std::string code, std::string field, std::string message, bool error = false) {
  check.flags.push_back({std::move(code), std::move(field), std::move(message), error});
}

std::string FieldOf(const InputError& e) {
  const std::string& q = e.quantity();
  for (const char* f : {"L", "H", "D", "Y", "u_L", "u_H", "u_D", "u_Y"})
    if (q == f) return f;
  return "";
}

}  // namespace

Configuration RowConfiguration(const ExperimentState& state, const Row& row) {
  return ParseConfiguration(MakeSource(state, row, state.Columns()));
}

namespace {

RowCheck Check(const Context& context, const Row& row) {
  const ExperimentState& state = *context.state;
  RowCheck check;
  if (!state.exists || !state.metadata.is_object()) {
    Add(check, "invalid", "", "create the experiment first (body, apparatus, units)", true);
    return check;
  }
  const std::vector<std::string> columns = state.Columns();
  const bool stored = state.IndexOf(row.id) >= 0;
  // Per-field checks on the numbers as typed.
  std::set<std::string> mixed;
  for (const char* q : {"L", "H", "D", "Y"}) {
    if (std::find(columns.begin(), columns.end(), q) == columns.end()) continue;
    const auto v = Si(row, q, state.unit);
    if (!v) continue;
    const Range range = kPlausible.at(q);
    const bool plausible = *v >= range.low && *v <= range.high;
    std::optional<std::string> mix;
    if (std::string(q) != "Y") {
      const auto it = context.sorted.find(q);
      if (it != context.sorted.end())
        if (const auto median = Median(it->second, stored ? v : std::nullopt)) mix = MixUp(*v, *median, state.unit);
    }
    if (!mix && !plausible && state.unit != "in" && std::string(q) != "H") {
      const double as_inches = *v / UnitFactor(Dimension::kLength, state.unit) * kInch;
      if (as_inches >= range.low && as_inches <= range.high)
        mix = "looks like inches typed in a " + state.unit + " field (as inches: " + Format(as_inches, state.unit) + ")";
    }
    if (mix) {
      Add(check, "unit_mixup", q, std::string(q) + " " + *mix);
      mixed.insert(q);
    } else if (!plausible) {
      Add(check, "implausible", q,
          std::string(q) + " = " + Format(*v, state.unit) + " is outside the plausible range " +
              Format(range.low, state.unit) + " – " + Format(range.high, state.unit));
    }
  }
  if (const auto L = Si(row, "L", state.unit), H = Si(row, "H", state.unit); L && H && *H >= *L)
    Add(check, "implausible", "H", "H ≥ L: the rails would rise at 45° or more");
  // The model.
  try {
    const Configuration c = ParseConfiguration(MakeSource(state, row, columns));
    PropagationOptions p;
    p.trials = 0;  // first order only: fast enough for every keystroke
    const PropagationResult r = Propagate(c.MakeUncertainRails(), c.MakeUncertainBody(), c.rod_radius, p);
    check.theta = r.theta.value;
    check.alpha = r.alpha.value;
    check.x_max = r.x_max.value;
    if (r.x_eq) {
      check.x_eq = r.x_eq->value;
      check.u_x_eq = r.x_eq->u_first_order;
    }
    check.crossbar = c.CrossbarDistance();
  } catch (const InputError& e) {
    Add(check, "invalid", FieldOf(e), e.what(), true);
  }
  if (!row.video.empty() && row.Value("Y").empty()) {
    // Y comes from the video's rest position (accepted in the page, or by the report).
  } else try {
    const FieldSource source = MakeSource(state, row, columns);
    const auto y = source.lookup("Y");
    check.y = ParseQuantity(y ? y->text : "", Dimension::kLength, "Y", y ? y->default_unit : "");
    if (!(*check.y > 0)) throw InputError("Y", "must be > 0 (a position beyond O)");
    check.u_y = 0.0;
    if (const auto uy = source.lookup("u_Y")) check.u_y = ParseQuantity(uy->text, Dimension::kLength, "u_Y", uy->default_unit);
  } catch (const InputError& e) {
    check.y.reset();
    Add(check, "invalid", "Y", e.what(), true);
  }
  if (check.x_eq && check.crossbar && *check.x_eq > *check.crossbar)
    Add(check, "x_beyond_crossbar", "", "X = " + Format(*check.x_eq, state.unit) + " is beyond the crossbar (" +
                                            Format(*check.crossbar, state.unit) + "): the apparatus cannot show the effect");
  if (check.y && check.x_eq) {
    const double residual = *check.y - *check.x_eq;
    const double u = std::hypot(check.u_x_eq.value_or(0), check.u_y.value_or(0));
    if (!mixed.count("Y"))
      if (const auto mix = MixUp(*check.y, *check.x_eq, state.unit)) {
        Add(check, "unit_mixup", "Y", "Y " + *mix + " (compared with X)");
        mixed.insert("Y");
      }
    if (!mixed.count("Y") && std::abs(residual) > 3 * u && std::abs(residual) > 0.2 * *check.x_eq)
      Add(check, "y_far", "Y", "Y − X = " + Format(residual, state.unit) + ": far from the prediction X = " +
                                   Format(*check.x_eq, state.unit) + " (check Y and the setting)");
  }
  if (check.y && check.x_max && *check.y > *check.x_max)
    Add(check, "y_beyond_fall_off", "Y", "Y is beyond the fall-off x_max = " + Format(*check.x_max, state.unit) +
                                             ": the body would have fallen through");
  if (const auto it = context.by_trial.find(row.trial); it != context.by_trial.end())
    if (std::any_of(it->second.begin(), it->second.end(), [&](std::int64_t id) { return id != row.id; }))
      Add(check, "duplicate_trial", "trial", "trial label \"" + row.trial + "\" is used by another row");
  if (const auto it = context.by_values.find(ValuesKey(row, state)); it != context.by_values.end())
    for (std::int64_t id : it->second)
      if (id != row.id) {
        const int i = state.IndexOf(id);
        Add(check, "duplicate_row", "", "same L, H, D and Y as trial \"" + state.rows[i].trial + "\" (typed twice?)");
        break;
      }
  return check;
}

json Number(std::optional<double> v, double scale = 1.0) { return v ? json(*v * scale) : json(nullptr); }

}  // namespace

RowCheck CheckRow(const ExperimentState& state, const Row& row) { return Check(MakeContext(state), row); }

ordered_json ToJson(const RowCheck& check, const std::string& unit) {
  const double to_unit = 1.0 / UnitFactor(Dimension::kLength, unit);
  const double to_deg = 180.0 / M_PI;
  ordered_json j;
  j["theta_deg"] = Number(check.theta, to_deg);
  j["alpha_deg"] = Number(check.alpha, to_deg);
  j["x"] = Number(check.x_eq, to_unit);
  j["u_x"] = Number(check.u_x_eq, to_unit);
  j["x_max"] = Number(check.x_max, to_unit);
  j["crossbar"] = Number(check.crossbar, to_unit);
  j["y"] = Number(check.y, to_unit);
  j["residual"] = check.y && check.x_eq ? json((*check.y - *check.x_eq) * to_unit) : json(nullptr);
  j["flags"] = ordered_json::array();
  for (const RowFlag& f : check.flags)
    j["flags"].push_back({{"code", f.code}, {"field", f.field}, {"message", f.message},
                          {"severity", f.error ? "error" : "warning"}});
  return j;
}

ordered_json CheckAll(const ExperimentState& state) {
  const Context context = MakeContext(state);
  const double to_unit = 1.0 / UnitFactor(Dimension::kLength, state.unit);
  ordered_json out;
  out["checks"] = ordered_json::array();
  LineData data;
  for (const Row& row : state.rows) {
    const RowCheck c = Check(context, row);
    ordered_json j = {{"id", row.id}};
    const ordered_json check = ToJson(c, state.unit);
    for (const auto& [k, v] : check.items()) j[k] = v;
    out["checks"].push_back(j);
    if (c.x_eq && c.y) {
      data.x.push_back(*c.x_eq * to_unit);
      data.y.push_back(*c.y * to_unit);
    }
  }
  ordered_json fit = {{"n", data.size()}};
  try {
    if (data.size() < 2) throw InputError("fit", "needs at least 2 rows with X and Y");
    const FitReport r = FitOrdinaryLeastSquares(data);
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
