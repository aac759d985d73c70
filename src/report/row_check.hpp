// CheckRow: the one check of a row of an experiment — what the page shows beside a row as it is
// typed, what `uphill fit` and `uphill report` print in a row's flags, and what Python's
// uphill.check_row returns. The model's θ, α, X ± u(X) (first-order propagation only, so that
// every keystroke can ask), x_max and the crossbar distance, and flags for the mistakes
// technicians make.
//
// Why here (report) and not in app: the report's analysis (AnalyseExperiment, analysis.hpp)
// attaches each row's flags, and report may not see app (the layer order is model ← io, fit,
// motion, vision ← report ← app). So the rules live once, here, and app/row_check.hpp offers them
// as the use case to the page and Python.
//
// Flags: code, field (the measurements.csv quantity to mark, or ""), message, severity. Every
// length in a message is in the experiment's unit (the Y column's, else mm). u below is the
// combined standard uncertainty sqrt(u(X)² + u(Y)²), u(X) by first-order propagation.
//   invalid            (error) the row cannot be analysed: its error from the experiment's reader
//                      (io/experiment.hpp: file, row, column, rule), or a model value that is not
//                      finite. The row's field is the column the error names.
//   implausible        a value outside what the apparatus can be: L ∉ [50 mm, 5 m], H ∉ [0, 2 m]
//                      or H ≥ L (rails at 45° or more), D ∉ [3 mm, 1 m], Y ∉ (0, 5 m]. Wide on
//                      purpose: a flag must mean "look again".
//   unit_mixup         a value that looks typed in another unit than its column's: within a
//                      factor 1.6 of (1 inch / column unit)⁻¹ (inches in a mm or cm column), 1.45
//                      of 1/10 (cm in a mm column) or 1.6 of 25.4 (mm in an inch column) times the
//                      other rows' median of that column — for Y, times X. The two factors keep
//                      the inch and cm bands apart while allowing for settings that differ within
//                      a series and for Y lying beyond X. Without other rows: a value that is
//                      implausible while, read as inches, it is not. Only for a column whose
//                      header names its unit (a cell that names its own unit was not slipped).
//   y_below_x          Y < X − 2u: the body rests beyond the unstable equilibrium X (rolling
//                      resistance only holds it farther out), so a Y on the near side of X by
//                      more than the measurements' scatter cannot be a rest position ("the body
//                      cannot rest there").
//   y_far              |Y − X| > 3u and > 20 % of X: far from the prediction (a slip in Y or in
//                      the setting); not raised with y_below_x.
//   y_beyond_fall_off  Y > x_max + 2u: beyond the fall-off the body would have fallen through.
//   x_beyond_crossbar  X > the crossbar distance (horizontal): the apparatus cannot show the effect.
//   duplicate_trial    another row has this trial label. The reader refuses the later row (it is
//                      left out of the analysis), so there the flag is an error, and not
//                      repeated as `invalid`.
//   duplicate_row      another row has the same L, H, D and Y cells (typed twice?).
//   u_disagrees        u(X) by first order and by Monte Carlo differ by > 5 % (the first order is
//                      then not to be trusted). Raised only by the report's analysis, which runs
//                      the Monte Carlo (UncertaintyDisagreement below); the page's check is first
//                      order only.
// A mix-up in Y explains a Y far from or below X, so y_below_x and y_far are not raised with it.
// A setting flagged as mistyped (unit_mixup or implausible on L, H or D) makes X and x_max wrong
// as well: Y is then not judged against them (no Y flag but its own range), so the flag names the
// one cell to fix and not also the correct Y.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/experiment.hpp"

namespace uphill {

enum class FlagSeverity { kWarning, kError };

struct RowFlag {
  std::string code, field, message;
  FlagSeverity severity = FlagSeverity::kWarning;
};

// "warning" or "error".
const char* SeverityName(FlagSeverity severity);

struct RowCheck {
  // SI (m, rad); empty when they cannot be computed (x_eq: also for a double cone).
  std::optional<double> theta, alpha, x_eq, u_x_eq, x_max, crossbar, y, u_y;
  std::vector<RowFlag> flags;

  bool Has(const std::string& code) const;
};

// Checks `row` against `experiment`'s other rows (when `row` is one of experiment.rows it is not
// compared with itself). Never throws for a bad row: that becomes a flag.
RowCheck CheckRow(const Experiment& experiment, const ExperimentRow& row);

// Every row's check, in the order of experiment.rows (the other rows are gathered once).
std::vector<RowCheck> CheckRows(const Experiment& experiment);

// The u_disagrees flag (above), for the report's Monte Carlo.
RowFlag UncertaintyDisagreement();

// [{"code","field","message","severity"}…]: the flags as fit.json, the page and Python give them.
nlohmann::ordered_json FlagsJson(const std::vector<RowFlag>& flags);

}  // namespace uphill
