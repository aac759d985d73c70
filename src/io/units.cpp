#include "io/units.hpp"

#include <array>
#include <charconv>
#include <cmath>

#include "model/input_error.hpp"

namespace uphill {
namespace {

struct UnitEntry {
  Dimension dimension;
  std::string_view name;
  double factor;  // SI value of one unit
  bool listed;    // shown in messages (aliases are not)
};

constexpr double kPi = 3.14159265358979323846;

constexpr std::array<UnitEntry, 20> kUnits{{
    {Dimension::kLength, "mm", 1e-3, true},
    {Dimension::kLength, "cm", 1e-2, true},
    {Dimension::kLength, "m", 1.0, true},
    {Dimension::kLength, "km", 1e3, true},
    {Dimension::kLength, "um", 1e-6, true},
    {Dimension::kLength, "\xC2\xB5m", 1e-6, false},
    {Dimension::kLength, "in", 0.0254, true},
    {Dimension::kLength, "inch", 0.0254, false},
    {Dimension::kAngle, "deg", kPi / 180.0, true},
    {Dimension::kAngle, "rad", 1.0, true},
    {Dimension::kAcceleration, "m/s2", 1.0, true},
    {Dimension::kAcceleration, "m/s^2", 1.0, false},
    {Dimension::kAcceleration, "mm/s2", 1e-3, false},
    {Dimension::kAcceleration, "mm/s^2", 1e-3, false},
    {Dimension::kTime, "s", 1.0, true},
    {Dimension::kTime, "ms", 1e-3, true},
    {Dimension::kTime, "min", 60.0, false},
    {Dimension::kVelocity, "m/s", 1.0, true},
    {Dimension::kVelocity, "mm/s", 1e-3, true},
    {Dimension::kVelocity, "cm/s", 1e-2, true},
}};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string AcceptedUnits(Dimension dimension) {
  if (dimension == Dimension::kDimensionless) return "a plain number, no unit";
  std::string out;
  for (const auto& u : kUnits) {
    if (u.dimension != dimension || !u.listed) continue;
    if (!out.empty()) out += ", ";
    out += u.name;
  }
  return out;
}

double UnitFactor(Dimension dimension, std::string_view unit) {
  for (const auto& u : kUnits)
    if (u.dimension == dimension && u.name == unit) return u.factor;
  return 0.0;
}

double ParseQuantity(std::string_view text, Dimension dimension, const std::string& quantity,
                     std::string_view default_unit) {
  const std::string_view trimmed = Trim(text);
  if (trimmed.empty()) throw InputError(quantity, "is empty (expected a number with a unit)");
  double number = 0.0;
  const char* begin = trimmed.data();
  const char* end = begin + trimmed.size();
  // A leading '+' is allowed (spreadsheets write it); from_chars does not accept it. Only one
  // sign, though: without this check "+-5 mm" would be read as -5 mm (found by tests/fuzz).
  if (*begin == '+') {
    ++begin;
    if (begin < end && (*begin == '-' || *begin == '+'))
      throw InputError(quantity, "'" + std::string(trimmed) + "' is not a number");
  }
  const auto [ptr, ec] = std::from_chars(begin, end, number);
  if (ec == std::errc::result_out_of_range)
    throw InputError(quantity, "'" + std::string(trimmed) + "' is out of the range of a double");
  if (ec != std::errc() || ptr == begin)
    throw InputError(quantity, "'" + std::string(trimmed) + "' is not a number");
  if (!std::isfinite(number))
    throw InputError(quantity, "'" + std::string(trimmed) + "' is not a finite number");
  const std::string_view unit = Trim(std::string_view(ptr, end - ptr));
  if (dimension == Dimension::kDimensionless) {
    if (!unit.empty())
      throw InputError(quantity, "'" + std::string(trimmed) + "' must be a plain number, without a unit");
    return number;
  }
  const std::string_view used = unit.empty() ? default_unit : unit;
  if (used.empty())
    throw InputError(quantity, "'" + std::string(trimmed) + "' has no unit (accepted: " +
                                   AcceptedUnits(dimension) + ")");
  const double factor = UnitFactor(dimension, used);
  if (factor == 0.0)
    throw InputError(quantity, "unit '" + std::string(used) + "' is not accepted here (accepted: " +
                                   AcceptedUnits(dimension) + ")");
  // The number is finite, but in SI it can overflow ("1e307 km" is 1e310 m; found by fuzzing).
  const double si = number * factor;
  if (!std::isfinite(si))
    throw InputError(quantity, "'" + std::string(trimmed) + "' is out of the range of a double");
  return si;
}

double ToUnit(double value_si, Dimension dimension, std::string_view unit) {
  if (dimension == Dimension::kDimensionless) return value_si;
  const double factor = UnitFactor(dimension, unit);
  if (factor == 0.0)
    throw InputError("unit", "'" + std::string(unit) + "' is not accepted (accepted: " +
                                 AcceptedUnits(dimension) + ")");
  return value_si / factor;
}

std::pair<std::string, std::string> SplitUnitSuffix(const std::string& header) {
  const auto pos = header.rfind('_');
  if (pos == std::string::npos || pos == 0) return {header, ""};
  const std::string suffix = header.substr(pos + 1);
  for (const auto& u : kUnits)
    if (u.name == suffix) return {header.substr(0, pos), suffix};
  return {header, ""};
}

std::vector<double> ParseQuantityList(const std::string& text, Dimension dimension, const std::string& quantity) {
  std::vector<double> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    out.push_back(ParseQuantity(std::string_view(text).substr(start, comma == std::string::npos ? std::string::npos
                                                                                                : comma - start),
                                dimension, quantity));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

}  // namespace uphill
