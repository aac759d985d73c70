// The text checks that experiment_state.cpp and experiment_metadata.cpp share: a request's
// text fit for a CSV cell and an HTML page.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace uphill::internal {

// The string `j`, valid UTF-8, at most `max_length` bytes, without control characters (a line
// break in a label would split a CSV row for a careless reader). Throws InputError(field, rule).
std::string CheckText(const nlohmann::json& j, const std::string& field, std::size_t max_length);

// `s` without leading and trailing spaces and tabs.
std::string Trim(const std::string& s);

}  // namespace uphill::internal
