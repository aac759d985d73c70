#include "model/input_error.hpp"

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

}  // namespace uphill
