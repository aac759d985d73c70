#include "model/input_error.hpp"
#include "model/length_range.hpp"

#include <cmath>
#include <sstream>

namespace uphill {

void RequirePositiveFinite(const std::string& quantity, double value) {
  if (std::isnan(value)) throw InputError(quantity, "must be a number (got NaN)");
  if (std::isinf(value)) throw InputError(quantity, "must be finite (got infinity)");
  if (value <= 0.0) {
    std::ostringstream rule;
    rule.precision(17);
    rule << "must be > 0 (got " << value << ")";
    throw InputError(quantity, rule.str());
  }
}

void RequireModelLength(const std::string& quantity, double metres) {
  if (!std::isfinite(metres)) throw InputError(quantity, "must be finite");
  const double size = std::abs(metres);
  if (size != 0.0 && (size < kShortestModelLength || size > kLongestModelLength)) {
    std::ostringstream rule;
    rule.precision(6);
    rule << "must lie between 1 nm and 1000 km (got " << metres
         << " m): the model is meant for lengths of an apparatus, and its numbers overflow far outside them";
    throw InputError(quantity, rule.str());
  }
}

}  // namespace uphill
