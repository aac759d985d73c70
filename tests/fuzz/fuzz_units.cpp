// Fuzz target: io::ParseQuantity (units.hpp) for every dimension, with and without a default
// unit (a CSV header suffix). Input: byte 0 picks the dimension, byte 1 the default unit, the
// rest is the text. Beyond "no crash, only InputError" it checks the documented contract: an
// accepted value is finite, a dimensionless one has no unit, and an accepted text has a plain
// number (one optional sign).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace {

using uphill::io::Dimension;

constexpr Dimension kDimensions[] = {Dimension::kLength, Dimension::kAngle, Dimension::kAcceleration,
                                     Dimension::kDimensionless};
constexpr const char* kDefaultUnits[] = {"", "mm", "in", "km", "um", "deg", "rad", "m/s2", "x", "m"};

[[noreturn]] void Fail(const char* what, std::string_view text) {
  std::fprintf(stderr, "fuzz_units: %s for '%.*s'\n", what, static_cast<int>(text.size()), text.data());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const Dimension dimension = kDimensions[data[0] % 4];
  const std::string default_unit = kDefaultUnits[data[1] % 10];
  const std::string_view text(reinterpret_cast<const char*>(data + 2), size - 2);
  try {
    const double v = uphill::io::ParseQuantity(text, dimension, "q", default_unit);
    if (!std::isfinite(v)) Fail("accepted a non-finite value", text);
    // No "+-5", "++5" or "-+5": at most one sign before the digits.
    const auto first = text.find_first_not_of(" \t\n\v\f\r");
    const std::string_view t = text.substr(first);
    if (t.size() >= 2 && (t[0] == '+' || t[0] == '-') && (t[1] == '+' || t[1] == '-'))
      Fail("accepted two signs", text);
    if (dimension != Dimension::kDimensionless && !default_unit.empty()) {
      // ToUnit is ParseQuantity's inverse for an accepted unit.
      const double factor = uphill::io::UnitFactor(dimension, default_unit);
      if (factor != 0.0 && !std::isfinite(uphill::io::ToUnit(v, dimension, default_unit)))
        Fail("ToUnit gave a non-finite value", text);
    }
  } catch (const uphill::InputError&) {
    // The documented refusal.
  }
  (void)uphill::io::SplitUnitSuffix(std::string(text));
  return 0;
}
