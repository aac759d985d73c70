// The lengths the model is meant for and answers for without overflow: 1 nm to 1000 km (the
// reference tests span micrometres to kilometres; squares and products of such lengths and of
// the ratios between them stay far inside binary64). 0 is let through (a height of 0, line
// rails): the model's own rules judge it, and the sign.
#pragma once

#include <string>

namespace uphill {

inline constexpr double kShortestModelLength = 1e-9, kLongestModelLength = 1e6;  // m

// Throws InputError(quantity, …) for a length (m) outside ±[1 nm, 1000 km] other than 0, or one
// that is not finite.
void RequireModelLength(const std::string& quantity, double metres);

}  // namespace uphill
