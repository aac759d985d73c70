// Every case of physics_reference.json (60-digit values, see reference_cases.hpp for the
// tolerance rule) reproduced by the model: angles, equilibrium, fall-off, rest band, points
// along the path, the L-along-rail convention, and the double cone's closed form.
#include <gtest/gtest.h>

#include "model/scene.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

using nlohmann::json;
using testing::CaseBody;
using testing::CaseIdsWhere;
using testing::CaseRails;
using testing::CaseRodRadius;
using testing::Cond;
using testing::ReferenceCase;
using testing::RefValue;

json CondAt(const json& c, const std::string& key) {
  return c.contains("cond") && c.at("cond").contains(key) ? c.at("cond").at(key) : json();
}

bool IsSweep(const json& c) { return c.at("rails").contains("sweep"); }
bool IsCone(const json& c) { return c.at("body").at("type") == "double_cone"; }
bool IsApparatus(const json& c) { return c.at("rails").contains("apparatus"); }

std::string CaseName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

// Cases with one configuration (all but the sweeps).
class ReferenceCaseTest : public ::testing::TestWithParam<std::string> {};
// Sphere and spheroid cases (an equilibrium exists).
class EquilibriumCaseTest : public ::testing::TestWithParam<std::string> {};
// Cases given as crossbar measurements (L, H, D).
class ApparatusCaseTest : public ::testing::TestWithParam<std::string> {};
// Double-cone cases.
class ConeCaseTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceCaseTest, AnglesAndHalfAngle) {
  const json& c = ReferenceCase(GetParam());
  const json& out = c.at("outputs");
  const Rails rails = CaseRails(c.at("rails"));
  EXPECT_REF(rails.theta, out.at("theta"), 1.0);
  EXPECT_REF(rails.alpha, out.at("alpha"), 1.0);
  EXPECT_REF(rails.HalfAngleBetweenRails(), out.at("phi"), 1.0);
  if (out.contains("tan_theta")) EXPECT_REF(rails.tan_theta, out.at("tan_theta"), 1.0);
  if (out.contains("tan_half_alpha")) EXPECT_REF(rails.tan_half_alpha, out.at("tan_half_alpha"), 1.0);
}

TEST_P(EquilibriumCaseTest, EquilibriumFallOffAndRest) {
  const json& c = ReferenceCase(GetParam());
  const json& out = c.at("outputs");
  const Scene scene(CaseBody(c.at("body")), CaseRails(c.at("rails")), CaseRodRadius(c));
  EXPECT_REF(*scene.x_eq(), out.at("x_eq"), Cond(CondAt(c, "x_eq")));
  EXPECT_REF(*scene.z_eq(), out.at("z_eq"), 1.0);
  EXPECT_REF(scene.x_max(), out.at("x_max"), Cond(CondAt(c, "x_max")));
  EXPECT_REF(*scene.FallOffMargin(), out.at("x_max_minus_x_eq"), 1.0);
  EXPECT_REF(scene.At(scene.x_max()).z, out.at("z_at_x_max"), 1.0);
  const json& rest = out.at("rest");
  for (size_t i = 0; i < rest.size(); ++i) {
    const auto band = scene.Rest(rest[i].at("mu"));
    ASSERT_TRUE(band.has_value());
    const json cond = CondAt(c, "x_rest");
    EXPECT_REF(band->high, rest[i].at("x_rest"), Cond(cond.is_null() ? json() : cond[i]));
    if (rest[i].contains("x_rest_low")) EXPECT_REF(band->low, rest[i].at("x_rest_low"), 1e3);
  }
}

TEST_P(ReferenceCaseTest, PointsAlongThePath) {
  const json& c = ReferenceCase(GetParam());
  const json& out = c.at("outputs");
  const Scene scene(CaseBody(c.at("body")), CaseRails(c.at("rails")), CaseRodRadius(c));
  const json& points = out.at("points");
  const json conds = CondAt(c, "points");
  for (size_t i = 0; i < points.size(); ++i) {
    SCOPED_TRACE(points[i].value("where", ""));
    const json cond = conds.is_null() ? json::object() : conds[i];
    const PathPoint p = scene.At(points[i].at("x"));
    EXPECT_REF(p.z, points[i].at("z"), Cond(cond.value("z", json())));
    EXPECT_REF(p.dzdx, points[i].at("dzdx"), Cond(cond.value("dzdx", json())));
    EXPECT_REF(p.r_star, points[i].at("R_star"), Cond(cond.value("R_star", json())));
    // x_M has no listed cond; it is as conditioned as R* (same contact point).
    EXPECT_REF(p.x_contact, points[i].at("x_M"), Cond(cond.value("R_star", json())));
  }
}

TEST_P(ApparatusCaseTest, LengthMeasuredAlongARail) {
  const json& c = ReferenceCase(GetParam());
  const json& out = c.at("outputs");
  const json& ref = out.at("along_rail_convention");
  const json& app = c.at("rails").at("apparatus");
  EXPECT_REF(HorizontalDistance<double>(app.at("L"), app.at("H"), app.at("D"), LConvention::kAlongRail),
             ref.at("L_horizontal"), 1.0);
  const Scene scene(CaseBody(c.at("body")), CaseRails(c.at("rails"), LConvention::kAlongRail), CaseRodRadius(c));
  EXPECT_REF(scene.rails().theta, ref.at("theta"), 1.0);
  EXPECT_REF(scene.rails().alpha, ref.at("alpha"), 1.0);
  EXPECT_REF(scene.rails().HalfAngleBetweenRails(), ref.at("phi"), 1.0);
  EXPECT_REF(*scene.x_eq(), ref.at("x_eq"), 10.0);
  EXPECT_REF(*scene.z_eq(), ref.at("z_eq"), 10.0);
  EXPECT_REF(scene.x_max(), ref.at("x_max"), 10.0);
  for (const json& r : ref.at("rest")) EXPECT_REF(scene.Rest(r.at("mu"))->high, r.at("x_rest"), 10.0);
}

TEST_P(ConeCaseTest, DoubleConeClosedForm) {
  const json& c = ReferenceCase(GetParam());
  const json& out = c.at("outputs");
  const Scene scene(CaseBody(c.at("body")), CaseRails(c.at("rails")));
  const auto* cone = scene.cone();
  ASSERT_NE(cone, nullptr);
  EXPECT_REF(cone->A(), out.at("A"), 1.0);
  EXPECT_REF(cone->B(), out.at("B"), Cond(CondAt(c, "B")));
  EXPECT_REF(cone->Q(), out.at("Q"), 1.0);
  EXPECT_REF(cone->s(), out.at("s"), 1.0);
  EXPECT_REF(cone->psi(), out.at("psi"), 1.0);
  EXPECT_REF(*scene.theta0(), out.at("theta0"), Cond(CondAt(c, "theta0")));
  EXPECT_REF(*scene.theta0_fixed_phi(), out.at("theta0_fixed_phi"), 1.0);
  EXPECT_REF(cone->x_fall(), out.at("x_fall"), 1.0);
  EXPECT_REF(scene.x_max(), out.at("x_fall"), 1.0);
  EXPECT_REF(cone->z_fall(), out.at("z_fall"), Cond(CondAt(c, "B")));
  EXPECT_REF(cone->x_low(), out.at("x_low"), 10.0);
  EXPECT_EQ(scene.rolls_up(), out.at("rolls_up").get<bool>());
  for (const json& r : out.at("rest"))
    EXPECT_EQ(scene.RestsEverywhere(r.at("mu")), r.at("rests_everywhere").get<bool>());
}

INSTANTIATE_TEST_SUITE_P(PhysicsReference, ReferenceCaseTest,
                         ::testing::ValuesIn(CaseIdsWhere([](const json& c) { return !IsSweep(c); })),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(PhysicsReference, EquilibriumCaseTest,
                         ::testing::ValuesIn(CaseIdsWhere([](const json& c) {
                           return !IsSweep(c) && !IsCone(c);
                         })),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(PhysicsReference, ApparatusCaseTest,
                         ::testing::ValuesIn(CaseIdsWhere(IsApparatus)), CaseName);
INSTANTIATE_TEST_SUITE_P(PhysicsReference, ConeCaseTest, ::testing::ValuesIn(CaseIdsWhere(IsCone)),
                         CaseName);

// FIG. 5/6-type sweeps: x_eq, z_eq, x_max and rest positions at listed (θ, α).
TEST(SweepTest, EquilibriumAgainstPhiAndTheta) {
  for (const char* id : {"paper_xeq_vs_phi_theta1deg", "paper_xeq_vs_theta_phi30deg"}) {
    const json& c = ReferenceCase(id);
    const Body body = CaseBody(c.at("body"));
    for (const json& row : c.at("outputs").at("sweep")) {
      SCOPED_TRACE(std::string(id) + " " + row.dump().substr(0, 60));
      const Scene scene(body, Rails::FromAngles(row.at("theta"), row.at("alpha")));
      EXPECT_REF(scene.rails().HalfAngleBetweenRails(), row.at("phi"), 1.0);
      EXPECT_REF(*scene.x_eq(), row.at("x_eq"), 10.0);
      EXPECT_REF(*scene.z_eq(), row.at("z_eq"), 10.0);
      EXPECT_REF(scene.x_max(), row.at("x_max"), 10.0);
      for (const json& r : row.at("rest")) EXPECT_REF(scene.Rest(r.at("mu"))->high, r.at("x_rest"), 10.0);
    }
  }
}

}  // namespace
}  // namespace uphill::testing
