// InputError: the one exception type for physically or formally invalid input.
//
// Contract: the message names the quantity (a flag, a JSON key or a CSV column) and the rule
// broken, in one line, e.g. "D: must be > 0 (got -3 mm)". Readers of files catch it and prefix
// the file, row and column; the library itself never prints and never returns NaN for bad input.
#pragma once

#include <stdexcept>
#include <string>

namespace uphill {

class InputError : public std::invalid_argument {
 public:
  InputError(std::string quantity, std::string rule)
      : std::invalid_argument(quantity + ": " + rule),
        quantity_(std::move(quantity)),
        rule_(std::move(rule)) {}

  const std::string& quantity() const { return quantity_; }
  const std::string& rule() const { return rule_; }

 private:
  std::string quantity_;
  std::string rule_;
};

// Throws InputError unless value is finite and > 0. Used for every length of the model.
void RequirePositiveFinite(const std::string& quantity, double value);

}  // namespace uphill
