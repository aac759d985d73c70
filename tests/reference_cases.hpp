// Access to tests/data/physics_reference.json (a copy of shared/reference, 60-digit values).
//
// Tolerance rule of the reference file: a binary64 result is expected within
// max(1e-12, 16·cond·1.1e-16) relative error, cond being the condition number the case lists
// for that value (1 when not listed); absolute 1e-15 where the reference value is 0.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/scene.hpp"

namespace uphill::testing {

const nlohmann::json& ReferenceFile();
// Ids of the cases for which keep(case) is true.
template <typename Predicate>
std::vector<std::string> CaseIdsWhere(Predicate keep) {
  std::vector<std::string> ids;
  for (const auto& c : ReferenceFile().at("cases"))
    if (keep(c)) ids.push_back(c.at("id").template get<std::string>());
  return ids;
}
const nlohmann::json& ReferenceCase(const std::string& id);

// The case's body, rails (apparatus cases in the given L convention) and rod radius (0 if none),
// and the Scene they make.
Body CaseBody(const nlohmann::json& body);
Rails CaseRails(const nlohmann::json& rails, LConvention convention = LConvention::kHorizontal);
double CaseRodRadius(const nlohmann::json& reference_case);
Scene CaseScene(const nlohmann::json& reference_case);

// Reference outputs are strings of 25 digits; parse to double (correctly rounded).
double RefValue(const nlohmann::json& v);
// cond listed for a value, 1 when absent.
double Cond(const nlohmann::json& cond_node);
// The allowed error for a reference value with condition number cond.
double Tolerance(double reference, double cond);

}  // namespace uphill::testing

// EXPECT that actual is within the reference-file tolerance of reference.
#define EXPECT_REF(actual, ref_json, cond)                                                \
  do {                                                                                   \
    const double uphill_ref_ = ::uphill::testing::RefValue(ref_json);                    \
    const double uphill_tol_ = ::uphill::testing::Tolerance(uphill_ref_, (cond));        \
    EXPECT_NEAR((actual), uphill_ref_, uphill_tol_) << "cond " << (cond) << ", " #actual; \
  } while (0)
