// The row check as a use case (CheckRow): the one check of a row that the page
// (src/server), `uphill fit`, `uphill report` and Python (uphill.check_row) all show.
//
// The rules themselves — every flag, its rule, its threshold and why — are in
// report/row_check.hpp: the report's analysis attaches them to each analysed row, and report
// may not see app (model ← io, fit, motion, vision ← report ← app), so they live there once and this
// header offers them to the front ends with the one serialisation they share.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "io/experiment.hpp"
#include "report/row_check.hpp"

namespace uphill {

// CheckRow(experiment, row) and CheckRows(experiment): report/row_check.hpp.

// A check as the page and Python receive it, lengths in `unit` ("mm", "cm", "m", "in"), angles
// in degrees, absent numbers as null:
//   {"theta_deg","alpha_deg","x","u_x","x_max","crossbar","y","u_y","residual",
//    "flags":[{"code","field","message","severity"}]}
// residual = y − x when both are known. Throws InputError for an unknown unit.
nlohmann::ordered_json RowCheckJson(const RowCheck& check, const std::string& unit);

}  // namespace uphill
