#include "report/quoted_value.hpp"

#include <cmath>

#include "model/number_text.hpp"

namespace uphill {

QuotedValue QuoteValue(double value, double u) {
  QuotedValue q;
  if (!std::isfinite(value)) {
    q.value = q.concise = "-";
    return q;
  }
  if (!(u > 0.0) || !std::isfinite(u)) {
    q.value = q.concise = Printf("%.6g", value);
    return q;
  }
  // Two significant digits of u: its leading digit's decade e, decimals 1 − e (none above 10).
  int decimals = 1 - static_cast<int>(std::floor(std::log10(u)));
  // Rounding may carry u into the next decade (0.0996 → "0.10"): then one digit less is enough.
  if (decimals > 0 && std::abs(std::round(u * std::pow(10.0, decimals))) >= 100.0) --decimals;
  if (decimals < 0) decimals = 0;
  q.decimals = decimals;
  const std::string format = "%." + std::to_string(decimals) + "f";
  q.value = Printf(format.c_str(), value);
  // No "-0.000": a value that rounds to zero has no sign.
  if (q.value.rfind('-', 0) == 0 && q.value.find_first_not_of("-0.") == std::string::npos) q.value.erase(0, 1);
  q.uncertainty = Printf(format.c_str(), u);
  // The uncertainty in units of the value's last digit: its digits without the point and the
  // leading zeros ("0.0012" → "12", "1.2" → "12", "16" → "16").
  std::string digits;
  for (const char c : q.uncertainty)
    if (c != '.' && !(digits.empty() && c == '0')) digits += c;
  q.concise = q.value + "(" + (digits.empty() ? "0" : digits) + ")";
  return q;
}

}  // namespace uphill
