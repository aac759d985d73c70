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

// EnvironmentError: the computer, not the input's content, refused: a file or folder that cannot
// be written or read (permissions, a full disk, a read-only folder), a helper program that is
// missing (gnuplot), a port in use. Like InputError it is the user's to fix, never a bug: the
// program reports it in one line naming the path, program or port and the system's reason, and
// exits with status 2.
class EnvironmentError : public std::runtime_error {
 public:
  explicit EnvironmentError(const std::string& message) : std::runtime_error(message) {}
};

// Throws InputError unless value is finite and > 0. Used for every length of the model.
void RequirePositiveFinite(const std::string& quantity, double value);

// The lengths the model is meant for and answers for without overflow: 1 nm to 1000 km (the
// reference tests span micrometres to kilometres; squares and products of such lengths and of
// the ratios between them stay far inside binary64). 0 is let through (a height of 0, line
// rails): the model's own rules judge it, and the sign.
inline constexpr double kShortestModelLength = 1e-9, kLongestModelLength = 1e6;  // m
// Throws InputError(quantity, …) for a length (m) outside ±[1 nm, 1000 km] other than 0, or one
// that is not finite.
void RequireModelLength(const std::string& quantity, double metres);

}  // namespace uphill
