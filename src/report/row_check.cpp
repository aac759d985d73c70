#include "report/row_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/propagation.hpp"

namespace uphill {
namespace {

constexpr double kInch = 0.0254;

struct Range {
  double low, high;
};
// What the apparatus can physically be (SI), header's contract.
const std::map<std::string, Range>& Plausible() {
  static const std::map<std::string, Range> ranges = {
      {"L", {0.05, 5.0}}, {"H", {0.0, 2.0}}, {"D", {0.003, 1.0}}, {"Y", {1e-9, 5.0}}};
  return ranges;
}

// The experiment's other rows, gathered once for every row's check.
struct Context {
  const Experiment* experiment = nullptr;
  std::string unit;                                        // of the messages
  std::map<std::string, std::vector<double>> sorted;       // quantity -> the rows' cells, sorted
  std::map<std::string, std::vector<std::size_t>> by_values;  // "L|H|D|Y" -> row indices
  std::map<std::string, std::vector<std::size_t>> by_trial;
};

std::string Format(double v, const std::string& unit) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g %s", ToUnit(v, Dimension::kLength, unit), unit.c_str());
  return buf;
}

std::optional<double> Cell(const ExperimentRow& row, const std::string& q) {
  const auto it = row.cells.find(q);
  return it == row.cells.end() ? std::nullopt : std::optional<double>(it->second);
}

// The cells that make two rows "the same": empty when the row has no Y cell (a video trial's
// setting may well be repeated).
std::string ValuesKey(const ExperimentRow& row) {
  if (!Cell(row, "Y")) return "";
  std::string key;
  for (const char* q : {"L", "H", "D", "Y"}) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.12g|", Cell(row, q).value_or(-1.0));
    key += buf;
  }
  return key;
}

std::string ColumnUnit(const Experiment& e, const std::string& q) {
  const auto it = e.column_units.find(q);
  return it == e.column_units.end() ? "" : it->second;
}

Context MakeContext(const Experiment& e) {
  Context c;
  c.experiment = &e;
  c.unit = ColumnUnit(e, "Y").empty() ? "mm" : ColumnUnit(e, "Y");
  for (std::size_t i = 0; i < e.rows.size(); ++i) {
    const ExperimentRow& r = e.rows[i];
    for (const char* q : {"L", "H", "D", "Y"})
      if (const auto v = Cell(r, q)) c.sorted[q].push_back(*v);
    if (const std::string key = ValuesKey(r); !key.empty()) c.by_values[key].push_back(i);
    c.by_trial[r.trial].push_back(i);
  }
  for (auto& [q, v] : c.sorted) std::sort(v.begin(), v.end());
  return c;
}

// Median of `sorted` without one instance of `self` (the row's own cell), or of all.
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

// How value/reference looks when a value of a `unit` column was typed in another unit (header).
std::optional<std::string> MixUp(double value, double reference, const std::string& unit) {
  if (!(reference > 0) || !(value > 0)) return std::nullopt;
  const double r = value / reference;
  const auto near = [&](double target, double factor) { return std::abs(std::log(r / target)) < std::log(factor); };
  const double per_unit = UnitFactor(Dimension::kLength, unit);
  if (unit != "in" && near(per_unit / kInch, 1.6))
    return "looks like inches typed in a " + unit + " column (as inches: " + Format(value / per_unit * kInch, unit) + ")";
  if (unit == "mm" && near(0.1, 1.45)) return std::string("looks like cm typed in a mm column (×10)");
  if (unit == "in" && near(kInch / 0.001, 1.6)) return std::string("looks like mm typed in an inch column");
  return std::nullopt;
}

void Add(RowCheck& check, std::string code, std::string field, std::string message,
         FlagSeverity severity = FlagSeverity::kWarning) {
  check.flags.push_back({std::move(code), std::move(field), std::move(message), severity});
}

// implausible and unit_mixup of the cells as typed; returns the quantities that look mixed up.
std::set<std::string> CheckCells(const Context& context, const ExperimentRow& row, bool stored, RowCheck& check) {
  std::set<std::string> mixed;
  const std::string& unit = context.unit;
  for (const char* q : {"L", "H", "D", "Y"}) {
    const auto v = Cell(row, q);
    if (!v) continue;
    const Range range = Plausible().at(q);
    const bool plausible = *v >= range.low && *v <= range.high;
    const std::string column_unit = ColumnUnit(*context.experiment, q);
    std::optional<std::string> mix;
    if (!column_unit.empty() && std::string(q) != "Y") {
      const auto it = context.sorted.find(q);
      if (it != context.sorted.end())
        if (const auto median = Median(it->second, stored ? v : std::nullopt)) mix = MixUp(*v, *median, column_unit);
    }
    if (!mix && !plausible && !column_unit.empty() && column_unit != "in" && std::string(q) != "H") {
      const double as_inches = *v / UnitFactor(Dimension::kLength, column_unit) * kInch;
      if (as_inches >= range.low && as_inches <= range.high)
        mix = "looks like inches typed in a " + column_unit + " column (as inches: " + Format(as_inches, unit) + ")";
    }
    if (mix) {
      Add(check, "unit_mixup", q, std::string(q) + " " + *mix);
      mixed.insert(q);
    } else if (!plausible) {
      Add(check, "implausible", q,
          std::string(q) + " = " + Format(*v, unit) + " is outside the plausible range " + Format(range.low, unit) +
              " – " + Format(range.high, unit));
    }
  }
  if (const auto L = Cell(row, "L"), H = Cell(row, "H"); L && H && *H >= *L)
    Add(check, "implausible", "H", "H ≥ L: the rails would rise at 45° or more");
  return mixed;
}

// θ, α, X ± u(X), x_max and the crossbar from the row's configuration (first order only).
void Model(const ExperimentRow& row, RowCheck& check) {
  const Configuration& c = *row.configuration;
  try {
    PropagationOptions p;
    p.trials = 0;
    const PropagationResult r = Propagate(c.MakeUncertainRails(), c.MakeUncertainBody(), c.rod_radius, p);
    check.theta = r.theta.value;
    check.alpha = r.alpha.value;
    check.x_max = r.x_max.value;
    if (r.x_eq) {
      check.x_eq = r.x_eq->value;
      check.u_x_eq = r.x_eq->u_first_order;
    }
    check.crossbar = c.CrossbarDistance();
    for (const auto& v : {check.theta, check.alpha, check.x_max, check.x_eq, check.u_x_eq})
      if (v && !std::isfinite(*v))
        throw InputError("the setting", "the model's X or its uncertainty is not a finite number for these values");
  } catch (const InputError& e) {
    check.theta = check.alpha = check.x_eq = check.u_x_eq = check.x_max = check.crossbar = std::nullopt;
    Add(check, "invalid", "", e.what(), FlagSeverity::kError);
  }
}

// The checks of Y against the model: mix-up with X, below X, far from X, beyond the fall-off.
void CheckY(const std::string& unit, const std::string& y_unit, std::set<std::string>& mixed, RowCheck& check) {
  const bool setting_suspect = std::any_of(check.flags.begin(), check.flags.end(), [](const RowFlag& f) {
    return (f.code == "unit_mixup" || f.code == "implausible") && (f.field == "L" || f.field == "H" || f.field == "D");
  });
  if (setting_suspect) return;  // X and x_max rest on the suspect cell (header)
  if (check.x_eq) {
    const double residual = *check.y - *check.x_eq;
    const double u = std::hypot(check.u_x_eq.value_or(0), check.u_y.value_or(0));
    if (!mixed.count("Y") && !y_unit.empty())
      if (const auto mix = MixUp(*check.y, *check.x_eq, y_unit)) {
        Add(check, "unit_mixup", "Y", "Y " + *mix + " (compared with X = " + Format(*check.x_eq, unit) + ")");
        mixed.insert("Y");
      }
    if (mixed.count("Y")) {
      // the mix-up explains a Y far from X
    } else if (residual < -2 * u) {
      Add(check, "y_below_x", "Y", "Y − X = " + Format(residual, unit) + ": Y is below X = " + Format(*check.x_eq, unit) +
                                       " by more than 2u (" + Format(2 * u, unit) + "): the body cannot rest there");
    } else if (std::abs(residual) > 3 * u && std::abs(residual) > 0.2 * *check.x_eq) {
      Add(check, "y_far", "Y", "Y − X = " + Format(residual, unit) + ": far from the prediction X = " +
                                   Format(*check.x_eq, unit) + " (check Y and the setting)");
    }
  }
  if (check.x_max) {
    const double u = std::hypot(check.u_x_eq.value_or(0), check.u_y.value_or(0));
    if (*check.y > *check.x_max + 2 * u)
      Add(check, "y_beyond_fall_off", "Y", "Y is beyond the fall-off x_max = " + Format(*check.x_max, unit) +
                                               " by more than 2u: the body would have fallen through");
  }
}

RowCheck Check(const Context& context, const ExperimentRow& row) {
  const Experiment& e = *context.experiment;
  const std::string& unit = context.unit;
  RowCheck check;
  const bool stored = &row >= e.rows.data() && &row < e.rows.data() + e.rows.size();
  const auto others = [&](const std::vector<std::size_t>& indices) {
    std::vector<std::size_t> out;
    for (std::size_t i : indices)
      if (&e.rows[i] != &row) out.push_back(i);
    return out;
  };
  const auto trial_it = context.by_trial.find(row.trial);
  const std::vector<std::size_t> same_trial =
      trial_it == context.by_trial.end() || row.trial.empty() ? std::vector<std::size_t>{} : others(trial_it->second);
  const bool refused_duplicate = !row.error.empty() && row.error_column == "trial" && !same_trial.empty();
  if (!row.error.empty() && !refused_duplicate) Add(check, "invalid", row.error_column, row.error, FlagSeverity::kError);
  std::set<std::string> mixed = CheckCells(context, row, stored, check);
  if (row.configuration) Model(row, check);
  if (row.configuration && row.HasY()) {
    check.y = row.Y.value;
    check.u_y = row.Y.u;
  }
  if (check.x_eq && check.crossbar && *check.x_eq > *check.crossbar)
    Add(check, "x_beyond_crossbar", "", "X = " + Format(*check.x_eq, unit) + " is beyond the crossbar (" +
                                            Format(*check.crossbar, unit) + "): the apparatus cannot show the effect");
  if (check.y) CheckY(unit, ColumnUnit(e, "Y"), mixed, check);
  if (!same_trial.empty())
    Add(check, "duplicate_trial", "trial",
        "trial label \"" + row.trial + "\" is also used in row " + std::to_string(e.rows[same_trial.front()].row) +
            (refused_duplicate ? ": this row is left out of the analysis" : ""),
        refused_duplicate ? FlagSeverity::kError : FlagSeverity::kWarning);
  if (const std::string key = ValuesKey(row); !key.empty())
    if (const auto it = context.by_values.find(key); it != context.by_values.end())
      if (const auto same = others(it->second); !same.empty())
        Add(check, "duplicate_row", "", "same L, H, D and Y as trial \"" + e.rows[same.front()].trial + "\" (typed twice?)");
  return check;
}

}  // namespace

const char* SeverityName(FlagSeverity severity) { return severity == FlagSeverity::kError ? "error" : "warning"; }

bool RowCheck::Has(const std::string& code) const {
  return std::any_of(flags.begin(), flags.end(), [&](const RowFlag& f) { return f.code == code; });
}

RowCheck CheckRow(const Experiment& experiment, const ExperimentRow& row) {
  return Check(MakeContext(experiment), row);
}

std::vector<RowCheck> CheckRows(const Experiment& experiment) {
  const Context context = MakeContext(experiment);
  std::vector<RowCheck> out;
  out.reserve(experiment.rows.size());
  for (const ExperimentRow& row : experiment.rows) out.push_back(Check(context, row));
  return out;
}

RowFlag UncertaintyDisagreement() {
  return {"u_disagrees", "", "u(X): first order and Monte Carlo differ by > 5 %: quote the Monte Carlo's",
          FlagSeverity::kWarning};
}

nlohmann::ordered_json FlagsJson(const std::vector<RowFlag>& flags) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const RowFlag& f : flags)
    out.push_back({{"code", f.code}, {"field", f.field}, {"message", f.message}, {"severity", SeverityName(f.severity)}});
  return out;
}

}  // namespace uphill
