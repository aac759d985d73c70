// LineData: the rows of a straight-line fit Y = k·X + c.
//
// In the experiment X is the theoretical equilibrium x_eq of one apparatus setting and Y the
// measured farthest rest position, both in metres, but nothing here depends on units: every fit
// is invariant under X → a·X + b, Y → d·Y + e (the fits standardise the data internally).
//
// Uncertainties are standard uncertainties (one standard deviation) in the units of the value
// they belong to, uncorrelated between rows and between X and Y of one row. Empty means "not
// given". Which ones a method needs, and what it does with the others, is stated with the method.
//
// Validation (ValidateLineData; every fit calls it first) throws InputError naming the quantity
// and the rule: fewer than 2 rows, columns of different lengths, a non-finite value, all X equal,
// and - where the method needs them - missing, non-finite or non-positive uncertainties.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace uphill {

struct LineData {
  std::vector<double> x;    // X_i
  std::vector<double> y;    // Y_i
  std::vector<double> u_x;  // u(X_i) ≥ 0, or empty
  std::vector<double> u_y;  // u(Y_i) > 0, or empty

  std::size_t size() const { return x.size(); }
};

// What a method requires of the uncertainty columns.
enum class UncertaintyUse {
  kNone,       // ignored (OLS)
  kOptionalY,  // u(Y) used if given, then every u(Y_i) must be finite and > 0 (robust fit)
  kY,          // u(Y) required, finite and > 0 (WLS)
  kXY,         // u(Y) required, finite and > 0; u(X) required, finite and ≥ 0 (York)
};

// Throws InputError (see above). `method` names the fit in the messages, e.g. "WLS".
void ValidateLineData(const LineData& data, UncertaintyUse use, const std::string& method);

}  // namespace uphill
