#include "app/row_check.hpp"

#include <cmath>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

nlohmann::ordered_json Number(const std::optional<double>& v, double scale) {
  return v ? nlohmann::ordered_json(*v * scale) : nlohmann::ordered_json(nullptr);
}

}  // namespace

nlohmann::ordered_json RowCheckJson(const RowCheck& check, const std::string& unit) {
  const double per_unit = UnitFactor(Dimension::kLength, unit);
  if (!(per_unit > 0)) throw InputError("unit", "'" + unit + "' is not a length unit (" + AcceptedUnits(Dimension::kLength) + ")");
  const double to_unit = 1.0 / per_unit;
  const double to_deg = 180.0 / M_PI;
  nlohmann::ordered_json j;
  j["theta_deg"] = Number(check.theta, to_deg);
  j["alpha_deg"] = Number(check.alpha, to_deg);
  j["x"] = Number(check.x_eq, to_unit);
  j["u_x"] = Number(check.u_x_eq, to_unit);
  j["x_max"] = Number(check.x_max, to_unit);
  j["crossbar"] = Number(check.crossbar, to_unit);
  j["y"] = Number(check.y, to_unit);
  j["u_y"] = Number(check.u_y, to_unit);
  j["residual"] = check.y && check.x_eq ? nlohmann::ordered_json((*check.y - *check.x_eq) * to_unit)
                                        : nlohmann::ordered_json(nullptr);
  j["flags"] = FlagsJson(check.flags);
  return j;
}

}  // namespace uphill
