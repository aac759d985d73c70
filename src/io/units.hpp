// Units: every number that enters or leaves uphill through a person carries its unit.
//
// Inside the library everything is SI (metres, radians, m/s²). At the edges a quantity is text
// such as "15.875mm", "1.25 in", "10deg", "0.1745rad", "9.81m/s2". A bare number is refused
// with a message listing the accepted units, because a guessed unit is a silent 25.4× error.
//
// Accepted units:
//   length        m, cm, mm, um (also µm), km, in (also inch)
//   angle         deg, rad
//   acceleration  m/s2 (also m/s^2)
//   time          s, ms (also min)
//   velocity      m/s, mm/s, cm/s
//   dimensionless a plain number (e.g. a coefficient μ); a unit is then refused
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace uphill {

enum class Dimension { kLength, kAngle, kAcceleration, kDimensionless, kTime, kVelocity };

// "mm, cm, m, km, um, in" etc.: the accepted unit names of a dimension, for messages.
std::string AcceptedUnits(Dimension dimension);

// SI value of one unit of the given name, or 0 if the name is not a unit of that dimension.
double UnitFactor(Dimension dimension, std::string_view unit);

// Parses "<number><unit>" (spaces allowed between) into SI. If `text` has no unit and
// default_unit is non-empty, default_unit is used (a CSV column whose header names its unit).
// Throws InputError(quantity, rule) for an empty value, a non-number, NaN or infinity, a
// missing unit, or a unit of the wrong dimension.
double ParseQuantity(std::string_view text, Dimension dimension, const std::string& quantity,
                     std::string_view default_unit = {});

// A comma-separated list of quantities ("110mm,12cm"), each parsed as ParseQuantity does; an
// empty item is an empty value (refused).
std::vector<double> ParseQuantityList(const std::string& text, Dimension dimension, const std::string& quantity);

// The number in `value_si` expressed in `unit` (e.g. 0.0254 m in "in" -> 1).
double ToUnit(double value_si, Dimension dimension, std::string_view unit);

// Splits a column header "L_mm" into {"L", "mm"} when the suffix after the last '_' is a unit
// of any dimension; otherwise {header, ""}.
std::pair<std::string, std::string> SplitUnitSuffix(const std::string& header);

}  // namespace uphill
