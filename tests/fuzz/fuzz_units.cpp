// Fuzz target: ParseQuantity (units.hpp) for every dimension, with and without a default
// unit (a CSV header suffix). Input: byte 0 picks the dimension, byte 1 the default unit, the
// rest is the text. Beyond "no crash, only InputError" it checks the documented contract: an
// accepted value is finite, an accepted text has a plain number (one optional sign), and a bare
// number read with the default unit comes back from ToUnit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <string>
#include <string_view>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace {

using uphill::Dimension;

constexpr Dimension kDimensions[] = {Dimension::kLength,        Dimension::kAngle, Dimension::kAcceleration,
                                     Dimension::kDimensionless, Dimension::kTime,  Dimension::kVelocity};
constexpr const char* kDefaultUnits[] = {"",     "mm", "in", "km", "um", "deg",  "rad",
                                         "m/s2", "x",  "m",  "s",  "ms", "mm/s", "min"};
constexpr std::size_t kDimensionCount = std::size(kDimensions);
constexpr std::size_t kDefaultUnitCount = std::size(kDefaultUnits);

[[noreturn]] void Fail(const char* what, std::string_view text) {
  std::fprintf(stderr, "fuzz_units: %s for '%.*s'\n", what, static_cast<int>(text.size()), text.data());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const Dimension dimension = kDimensions[data[0] % kDimensionCount];
  const std::string default_unit = kDefaultUnits[data[1] % kDefaultUnitCount];
  const std::string_view text(reinterpret_cast<const char*>(data + 2), size - 2);
  try {
    const double v = uphill::ParseQuantity(text, dimension, "q", default_unit);
    if (!std::isfinite(v)) Fail("accepted a non-finite value", text);
    // No "+-5", "++5" or "-+5": at most one sign before the digits.
    const auto first = text.find_first_not_of(" \t\n\v\f\r");
    const std::string_view t = text.substr(first);
    if (t.size() >= 2 && (t[0] == '+' || t[0] == '-') && (t[1] == '+' || t[1] == '-'))
      Fail("accepted two signs", text);
    if (dimension != Dimension::kDimensionless && !default_unit.empty()) {
      // A bare number took the default unit: ToUnit gives the number back (away from the
      // subnormal range, where the SI value has lost digits).
      double number = 0.0;
      try {
        number = uphill::ParseQuantity(text, Dimension::kDimensionless, "q");
      } catch (const uphill::InputError&) {
        return 0;  // the text carries its own unit
      }
      const double back = uphill::ToUnit(v, dimension, default_unit);
      if (std::abs(v) > 1e-290 && !(std::abs(back - number) <= 1e-14 * std::abs(number)))
        Fail("ToUnit does not invert the default unit", text);
    }
  } catch (const uphill::InputError&) {
    // The documented refusal.
  }
  (void)uphill::SplitUnitSuffix(std::string(text));
  return 0;
}
