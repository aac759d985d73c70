// The page's row checks: what the page shows beside a row as it is typed. The server does not
// judge rows itself: it writes its state as the folder's files would be (experiment.json,
// measurements.csv), reads them back as `uphill fit` does (io/experiment.hpp) and asks the one
// row check (app/row_check.hpp; rules and thresholds in report/row_check.hpp), so the page, fit,
// report and Python flag the same rows with the same codes and words. Messages name the file,
// row and column ("measurements.csv, row 3, column D_mm: …").
//
// The fit summary is the ordinary least-squares line Y = k·X + c (fit/least_squares_line.hpp)
// over the rows whose X and Y are known and that are not excluded (a row's `excluded` reason:
// shown and checked, never fitted, as in `uphill fit`), with the usual (scaled) standard errors.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "app/row_check.hpp"
#include "io/configuration.hpp"
#include "io/experiment.hpp"
#include "server/experiment_state.hpp"

namespace uphill {

// The row's setting (body, rails, rods) from its cells and the experiment's constants. Throws
// InputError naming the field.
Configuration RowConfiguration(const ExperimentState& state, const Row& row);

// The state as the experiment reader sees its files (directory ""), rows in the state's order.
// Throws InputError when there is no experiment yet or its files cannot be read.
Experiment StateExperiment(const ExperimentState& state);

// Checks `row` as it would stand in the state: in place of the stored row with its id, or after
// the others (a new row). Never throws for bad input: that becomes an `invalid` flag.
RowCheck CheckRow(const ExperimentState& state, const Row& row);

// A row being typed: CheckRow, and for a row whose setting is complete but whose Y is not typed
// yet (and that has no video to give it), the setting's part of the check — θ, α, X ± u(X),
// x_max, the crossbar and the flags of L, H, D — so the page shows X, where to look for the body,
// before Y is measured. Nothing of Y is judged then (y, residual and Y's flags are absent).
RowCheck CheckDraft(const ExperimentState& state, const Row& row);

// The answer of POST /api/check for a row as the page sends it (`id` when editing):
// {"complete": true, ...ToJson(check)} for a row that could be saved; {"complete": false,
// "error", "field"} for one that could not (the first rule it breaks), with its CheckDraft's
// fields too when only Y is missing. Never throws for what the row holds.
nlohmann::ordered_json CheckAnswer(const ExperimentState& state, const nlohmann::json& row_json);

// RowCheckJson (app/row_check.hpp) in the experiment's unit.
nlohmann::ordered_json ToJson(const RowCheck& check, const std::string& unit);

// Every row's check (keyed by row id, in row order) and the OLS fit of the rows with X and Y:
//   {"checks":[{"id":..,<ToJson>}...],"fit":{"n","excluded","slope","intercept","u_slope",
//    "u_intercept","r_squared","residual_sd"} or {"n","excluded","unavailable":reason}}; fit lengths
//   in `unit`; n the rows fitted, excluded the rows left out by their `excluded` reason.
nlohmann::ordered_json CheckAll(const ExperimentState& state);

}  // namespace uphill
