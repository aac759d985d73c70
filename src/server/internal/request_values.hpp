// Numbers in requests, parsed strictly: a whole number must be one, within its range, and is
// reported as it was sent when it is refused (never wrapped or rounded first: "2147483648" is not
// taken as −2147483648, "1.9" not as 1, "1e300" not as the lowest 64-bit number). Private to
// src/server/.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace uphill::internal {

// A whole number of a query string ("42", "-3"): digits with an optional '-'. Throws
// InputError(field, "must be <what>, a whole number from lo to hi (got "text")") otherwise.
std::int64_t WholeNumberText(const std::string& text, const std::string& field, std::int64_t lo, std::int64_t hi,
                             const std::string& what);

// A whole number of a JSON body: an integer (not 2.0, not "2") within [lo, hi]. Throws
// InputError as WholeNumberText, the value shown as sent.
std::int64_t WholeNumberJson(const nlohmann::json& value, const std::string& field, std::int64_t lo, std::int64_t hi,
                             const std::string& what);

// A number of a query string, as JavaScript writes one ("12.5", "-3e-2"): whole text, finite.
// Throws InputError(field, "must be a number (got "text")").
double NumberText(const std::string& text, const std::string& field);

}  // namespace uphill::internal
