// The X-Y fit of the server's API (http_server.hpp lists the routes): the use case of
// app/fit_xy.hpp, as `uphill fit --xy FILE --method M --json` runs it. Private to src/server/.
#pragma once

#include <nlohmann/json.hpp>

namespace uphill::internal {

// POST /api/fit-xy {"method": "ols"|"wls"|"york"|"robust" (default "ols"), "x": [..], "y": [..],
// "u_x": [..] (optional), "u_y": [..] (optional)}: plain numbers, X and u_x in one unit, Y and u_y
// in one unit. Answers the JSON of `uphill fit --xy … --json` (docs/fit.md, "JSON output"), rows
// included. Throws InputError naming the request's field ("method", "x", "y[3]", "u_y[0]") and the
// rule, with the fit's own wording.
nlohmann::ordered_json FitXyAnswer(const nlohmann::json& body);

}  // namespace uphill::internal
