// CheckRow: what the page shows beside a row as it is typed — the model's θ, α and X ± u(X)
// (first-order propagation only: microseconds, so every keystroke can ask), the residual Y − X,
// and flags for the mistakes technicians make. The server computes these; the page's own checks
// are only a convenience.
//
// Flags (code, field, message; severity "error" when the row cannot be analysed as typed):
//   invalid            the configuration or Y cannot be made (ParseConfiguration's message)
//   implausible        a value outside what the apparatus can be: L ∉ [50 mm, 5 m], H ∉ [0, 2 m]
//                      or H ≥ L, D ∉ [3 mm, 1 m], Y ∉ (0, 5 m]
//   unit_mixup         a value that looks typed in another unit: within a factor 1.6 of 1/25.4
//                      (inches in a mm field) or 1.45 of 1/10 (cm in a mm field) times the other
//                      rows' median of that column (for Y: times X); without a reference, a value
//                      that is implausible while read as inches it is not
//   y_far              |Y − X| > 3·sqrt(u(X)² + u(Y)²) and > 20 % of X: far from the prediction
//   y_beyond_fall_off  Y > x_max: the body would have fallen through
//   x_beyond_crossbar  X > L (horizontal): the apparatus cannot show the effect
//   duplicate_trial    another row has this trial label (the report would drop one)
//   duplicate_row      another row has the same L, H, D and Y (typed twice?)
//
// The fit summary is the ordinary least-squares line Y = k·X + c (fit/least_squares_line.hpp)
// over the rows whose X could be computed, with the usual (scaled) standard errors.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "server/experiment_state.hpp"

namespace uphill {

struct RowFlag {
  std::string code, field, message;
  bool error = false;
};

struct RowCheck {
  // SI (m, rad); empty when they cannot be computed.
  std::optional<double> theta, alpha, x_eq, u_x_eq, x_max, crossbar, y, u_y;
  std::vector<RowFlag> flags;
};

// The row's setting (body, rails, rods) from its cells and the experiment's constants. Throws
// InputError naming the field.
Configuration RowConfiguration(const ExperimentState& state, const Row& row);

// Checks `row` against the experiment and the stored rows (a stored row with the same id is not
// compared with itself). Never throws for bad input: that becomes a flag.
RowCheck CheckRow(const ExperimentState& state, const Row& row);

// JSON for the page, lengths in the experiment's unit and angles in degrees:
//   {"theta_deg","alpha_deg","x","u_x","x_max","crossbar","y","residual","flags":[{code,field,
//    message,severity}]}, absent numbers as null.
nlohmann::ordered_json ToJson(const RowCheck& check, const std::string& unit);

// Every row's check (keyed by row id, in row order) and the OLS fit of the computable rows:
//   {"checks":[{"id":..,<ToJson>}...],"fit":{"n","slope","intercept","u_slope","u_intercept",
//    "r_squared","residual_sd"} or {"n","unavailable":reason}}; fit lengths in `unit`.
nlohmann::ordered_json CheckAll(const ExperimentState& state);

}  // namespace uphill
