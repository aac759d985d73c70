#include "fit_api.hpp"

#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "app/fit_xy.hpp"
#include "model/input_error.hpp"
#include "report/fit_json.hpp"

namespace uphill::internal {
namespace {

using nlohmann::json;

std::vector<double> Column(const json& body, const std::string& key, bool required) {
  if (!body.contains(key) || body.at(key).is_null()) {
    if (required) throw InputError(key, "is missing (an array of numbers)");
    return {};
  }
  const json& values = body.at(key);
  if (!values.is_array()) throw InputError(key, "must be an array of numbers");
  std::vector<double> out;
  out.reserve(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!values[i].is_number()) throw InputError(key + "[" + std::to_string(i) + "]", "must be a number");
    out.push_back(values[i].get<double>());
  }
  return out;
}

// The fit layer names a value by its column ("Y[3]", "u(X)[0]", "u(Y)"): the request's key.
InputError InRequestTerms(const InputError& e) {
  static const std::map<std::string, std::string> kKeys = {{"X", "x"}, {"Y", "y"}, {"u(X)", "u_x"}, {"u(Y)", "u_y"}};
  static const std::regex named(R"((X|Y|u\(X\)|u\(Y\))(\[\d+\])?)");
  std::smatch match;
  if (!std::regex_match(e.quantity(), match, named)) return e;
  return InputError(kKeys.at(match[1].str()) + match[2].str(), e.rule());
}

}  // namespace

nlohmann::ordered_json FitXyAnswer(const json& body) {
  if (!body.is_object()) throw InputError("request", "must be a JSON object");
  std::string method_name = kDefaultFitXyMethod;
  if (body.contains("method")) {
    if (!body.at("method").is_string()) throw InputError("method", "must be ols, wls, york or robust");
    method_name = body.at("method").get<std::string>();
  }
  const FitMethod method = ParseFitMethod(method_name, "method");
  const LineData data{Column(body, "x", true), Column(body, "y", true), Column(body, "u_x", false),
                      Column(body, "u_y", false)};
  FitXyOptions options;
  options.fit.keep_rows = false;  // streamed from the data, as the command writes them
  FitReport report;
  try {
    report = FitXy(method, data, options);
  } catch (const InputError& e) {
    throw InRequestTerms(e);
  }
  std::ostringstream text;
  WriteFitJson(text, report, data);
  return nlohmann::ordered_json::parse(text.str());
}

}  // namespace uphill::internal
