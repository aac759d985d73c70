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

const nlohmann::json& ReferenceCase(const std::string& id) {
  for (const auto& c : ReferenceFile().at("cases"))
    if (c.at("id") == id) return c;
  throw std::runtime_error("no reference case " + id);
}

Body CaseBody(const nlohmann::json& b) {
  const std::string type = b.at("type");
  if (type == "sphere") return Body::Sphere(b.at("R"));
  if (type == "spheroid") return Body::Spheroid(b.at("a"), b.at("b"));
  return Body::DoubleCone(b.at("R"), b.at("h"));
}

Rails CaseRails(const nlohmann::json& rails, LConvention convention) {
  if (rails.contains("apparatus")) {
    const nlohmann::json& app = rails.at("apparatus");
    return Rails::FromApparatus(app.at("L"), app.at("H"), app.at("D"), convention);
  }
  return Rails::FromAngles(rails.at("theta"), rails.at("alpha"));
}

double CaseRodRadius(const nlohmann::json& c) {
  return c.contains("rod_radius") && !c.at("rod_radius").is_null() ? c.at("rod_radius").get<double>() : 0.0;
}

Scene CaseScene(const nlohmann::json& c) { return Scene(CaseBody(c.at("body")), CaseRails(c.at("rails")), CaseRodRadius(c)); }

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
