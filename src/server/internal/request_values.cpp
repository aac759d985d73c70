#include "request_values.hpp"

#include <charconv>
#include <cmath>

#include "model/input_error.hpp"

namespace uphill::internal {
namespace {

[[noreturn]] void RefuseWhole(const std::string& field, const std::string& shown, std::int64_t lo, std::int64_t hi,
                              const std::string& what) {
  throw InputError(field, "must be " + what + ", a whole number from " + std::to_string(lo) + " to " +
                              std::to_string(hi) + " (got " + shown + ")");
}

std::string Quoted(const std::string& text) { return "\"" + text.substr(0, 40) + (text.size() > 40 ? "…" : "") + "\""; }

}  // namespace

std::int64_t WholeNumberText(const std::string& text, const std::string& field, std::int64_t lo, std::int64_t hi,
                             const std::string& what) {
  std::int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [at, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || text.front() == '+' || error != std::errc() || at != end || value < lo || value > hi)
    RefuseWhole(field, Quoted(text), lo, hi, what);
  return value;
}

std::int64_t WholeNumberJson(const nlohmann::json& value, const std::string& field, std::int64_t lo, std::int64_t hi,
                             const std::string& what) {
  const bool fits = value.is_number_unsigned() ? value.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi)
                                               : value.is_number_integer();
  if (!fits) RefuseWhole(field, value.dump().substr(0, 40), lo, hi, what);
  const std::int64_t v = value.get<std::int64_t>();
  if (v < lo || v > hi) RefuseWhole(field, value.dump(), lo, hi, what);
  return v;
}

double NumberText(const std::string& text, const std::string& field) {
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [at, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || at != end || !std::isfinite(value))
    throw InputError(field, "must be a number (got " + Quoted(text) + ")");
  return value;
}

}  // namespace uphill::internal
