#include "reference_cases.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace uphill::testing {

const nlohmann::json& ReferenceFile() {
  static const nlohmann::json file = [] {
    const std::string path = std::string(UPHILL_TEST_DATA_DIR) + "/physics_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    return nlohmann::json::parse(in);
  }();
  return file;
}

std::vector<std::string> ReferenceCaseIds() {
  std::vector<std::string> ids;
  for (const auto& c : ReferenceFile().at("cases")) ids.push_back(c.at("id").get<std::string>());
  return ids;
}

const nlohmann::json& ReferenceCase(const std::string& id) {
  for (const auto& c : ReferenceFile().at("cases"))
    if (c.at("id") == id) return c;
  throw std::runtime_error("no reference case " + id);
}

double RefValue(const nlohmann::json& v) {
  if (v.is_number()) return v.get<double>();
  return std::strtod(v.get<std::string>().c_str(), nullptr);  // correctly rounded (glibc)
}

double Cond(const nlohmann::json& cond_node) {
  if (cond_node.is_null()) return 1.0;
  return RefValue(cond_node);
}

double Tolerance(double reference, double cond) {
  if (reference == 0.0) return 1e-15;
  return std::abs(reference) * std::max(1e-12, 16.0 * cond * 1.1e-16);
}

}  // namespace uphill::testing
