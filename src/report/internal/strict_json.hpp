// StrictJson: reads a JSON document that is input (a cache entry another run wrote, which may be
// damaged or edited) with the checks any input gets: each key present with the right type, every
// number finite and in its range. A broken rule throws InputError naming the key's path
// ("events[2].x.value") and the rule.
#pragma once

#include <cmath>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "report/video_trials.hpp"

namespace uphill::internal {

class StrictJson {
 public:
  StrictJson(const nlohmann::json& j, std::string path) : j_(j), path_(std::move(path)) {
    if (!j_.is_object()) throw InputError(Where(""), "must be an object");
  }

  std::string Text(const char* key) const { return Typed(key, &nlohmann::json::is_string, "text").get<std::string>(); }
  bool Bool(const char* key) const { return Typed(key, &nlohmann::json::is_boolean, "true or false").get<bool>(); }
  std::string OneOf(const char* key, std::initializer_list<const char*> allowed) const {
    const std::string text = Text(key);
    for (const char* a : allowed)
      if (text == a) return text;
    throw InputError(Where(key), "'" + text + "' is not one of the values it may take");
  }
  int Integer(const char* key, int lo, int hi) const {
    const nlohmann::json& v = Typed(key, &nlohmann::json::is_number_integer, "a whole number");
    // An unsigned value beyond long long's range is out of range anyway.
    const long long n = v.is_number_unsigned() && v.get<unsigned long long>() > static_cast<unsigned long long>(hi)
                            ? static_cast<long long>(hi) + 1
                            : v.get<long long>();
    if (n < lo || n > hi)
      throw InputError(Where(key), std::to_string(n) + " is out of range [" + std::to_string(lo) + ", " +
                                       std::to_string(hi) + "]");
    return static_cast<int>(n);
  }
  double Number(const char* key, double lo, double hi) const { return InRange(At(key), Where(key), lo, hi); }
  // {"value": v, "u": u} or null: |v| ≤ max_value (null: NaN, not measured), 0 ≤ u ≤ max_u (null: none).
  std::optional<Estimate> Value(const char* key, double max_value, double max_u) const {
    const nlohmann::json& v = At(key);
    if (v.is_null()) return std::nullopt;
    const StrictJson o(v, Where(key));
    Estimate m;
    m.value = o.At("value").is_null() ? std::nan("") : o.Number("value", -max_value, max_value);
    if (!o.At("u").is_null()) m.u = o.Number("u", 0, max_u);
    return m;
  }
  std::vector<std::string> Texts(const char* key) const {
    std::vector<std::string> out;
    for (const nlohmann::json& e : Array(key)) {
      if (!e.is_string()) throw InputError(Where(key), "must hold text only");
      out.push_back(e.get<std::string>());
    }
    return out;
  }
  // Numbers with |x| ≤ max.
  std::vector<double> Numbers(const char* key, double max) const {
    std::vector<double> out;
    for (const nlohmann::json& e : Array(key)) out.push_back(InRange(e, Where(key), -max, max));
    return out;
  }
  // Pairs [a, b] with |a| ≤ max_first, |b| ≤ max_second.
  std::vector<std::pair<double, double>> Pairs(const char* key, double max_first, double max_second) const {
    std::vector<std::pair<double, double>> out;
    for (const nlohmann::json& e : Array(key)) {
      if (!e.is_array() || e.size() != 2) throw InputError(Where(key), "must hold pairs [t, x]");
      out.emplace_back(InRange(e[0], Where(key), -max_first, max_first), InRange(e[1], Where(key), -max_second, max_second));
    }
    return out;
  }
  StrictJson Object(const char* key) const { return StrictJson(At(key), Where(key)); }
  void ForEach(const char* key, const std::function<void(const StrictJson&)>& each) const {
    const nlohmann::json& a = Array(key);
    for (std::size_t i = 0; i < a.size(); ++i) each(StrictJson(a[i], Where(key) + "[" + std::to_string(i) + "]"));
  }

 private:
  std::string Where(const std::string& key) const {
    if (key.empty()) return path_.empty() ? "the document" : path_;
    return path_.empty() ? key : path_ + "." + key;
  }
  const nlohmann::json& At(const char* key) const {
    const auto it = j_.find(key);
    if (it == j_.end()) throw InputError(Where(key), "is missing");
    return *it;
  }
  const nlohmann::json& Typed(const char* key, bool (nlohmann::json::*is)() const noexcept, const char* type) const {
    const nlohmann::json& v = At(key);
    if (!(v.*is)()) throw InputError(Where(key), std::string("must be ") + type);
    return v;
  }
  const nlohmann::json& Array(const char* key) const { return Typed(key, &nlohmann::json::is_array, "a list"); }
  static double InRange(const nlohmann::json& v, const std::string& where, double lo, double hi) {
    if (!v.is_number()) throw InputError(where, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
      throw InputError(where, Printf("%g", x) + " is out of range [" + Printf("%g", lo) + ", " + Printf("%g", hi) + "]");
    return x;
  }

  const nlohmann::json& j_;
  std::string path_;
};

}  // namespace uphill::internal
