// Every `release` block of physics_reference.json (25-digit references of the release-from-rest
// dynamics) reproduced by both methods of src/motion: t at positions, the time to 0.99·x_max (or
// to x_max, or to 0.99·x_fall for the cone), and x at times. Tolerance of the release blocks:
// max(1e-10, 16·cond·1.1e-16) relative, cond as listed for each value (1 when absent).
#include <gtest/gtest.h>

#include <algorithm>

#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

using nlohmann::json;
using testing::CaseIdsWhere;
using testing::Cond;
using testing::ReferenceCase;
using testing::RefValue;


constexpr double kFloor = 1e-10;  // every scene, the spheroid on rods included (motion.hpp)
double ReleaseTolerance(double reference, double cond) {
  return std::abs(reference) * std::max(kFloor, 16.0 * cond * 1.1e-16);
}

#define EXPECT_RELEASE(actual, ref_json, cond) \
  EXPECT_NEAR((actual), RefValue(ref_json), ReleaseTolerance(RefValue(ref_json), (cond))) << "cond " << (cond) << ", " #actual

bool HasRelease(const json& c) { return c.at("outputs").contains("release"); }

struct Param {
  std::string id;
  MotionMethod method;
};

class ReleaseTest : public ::testing::TestWithParam<Param> {};

TEST_P(ReleaseTest, TimesAndPositions) {
  const json& c = ReferenceCase(GetParam().id);
  const json& rel = c.at("outputs").at("release");
  const json& cond = c.at("cond");
  const Scene scene = testing::CaseScene(c);
  MotionOptions o;
  o.g = rel.at("g");
  o.method = GetParam().method;
  const double x0 = rel.at("x0");
  const Motion motion(scene, x0, o);
  EXPECT_EQ(motion.direction(), 1);
  const json& tx = rel.at("t_at_x");
  for (size_t i = 0; i < tx.size(); ++i) {
    const double x = tx[i].at("x");
    EXPECT_RELEASE(motion.TimeAt(x), tx[i].at("t"), Cond(cond.at("t_at_x")[i])) << "x = " << x;
  }
  const double span = scene.x_max();
  if (rel.contains("t_to_0.99_x_max") && !rel.at("t_to_0.99_x_max").is_null()) { EXPECT_RELEASE(motion.TimeAt(0.99 * span), rel.at("t_to_0.99_x_max"), 1.0); }
  if (rel.contains("t_to_0.99_x_fall")) { EXPECT_RELEASE(motion.TimeAt(0.99 * span), rel.at("t_to_0.99_x_fall"), 1.0); }
  if (rel.contains("t_to_x_max")) {
    EXPECT_RELEASE(motion.TimeAt(span), rel.at("t_to_x_max"), 1.0);
    ASSERT_FALSE(motion.events().empty());
    EXPECT_EQ(motion.events().back().kind, MotionEventKind::kFallOff);
    EXPECT_RELEASE(motion.end_time(), rel.at("t_to_x_max"), 1.0);
  }
  const json& xt = rel.at("x_at_t");
  for (size_t i = 0; i < xt.size(); ++i) {
    const double t = xt[i].at("t");
    EXPECT_RELEASE(motion.At(t).x, xt[i].at("x"), Cond(cond.at("x_at_t")[i])) << "t = " << t;
  }
}

std::vector<Param> Params() {
  std::vector<Param> out;
  for (const auto& id : CaseIdsWhere(HasRelease)) {
    out.push_back({id, MotionMethod::kQuadrature});
    out.push_back({id, MotionMethod::kOde});
  }
  return out;
}

std::string Name(const ::testing::TestParamInfo<Param>& info) {
  std::string name = info.param.id + (info.param.method == MotionMethod::kOde ? "_ode" : "_quadrature");
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Reference, ReleaseTest, ::testing::ValuesIn(Params()), Name);

}  // namespace
}  // namespace uphill::testing
