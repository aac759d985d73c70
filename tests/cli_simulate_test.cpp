// `uphill simulate` end to end: JSON keys and values against the reference release, units at
// the edges (s, ms, m/s, m/s2), the three sampling modes, events, CSV, and exit code 2 with a
// one-line message naming the flag for bad input.
#include <gtest/gtest.h>

#include <vector>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

using nlohmann::json;
using testing::RunUphill;

// paper_fig4_b_over_a_1.6 (a = 20 mm, b = 32 mm, θ = 10°, α = 30°), released at its x0.
const std::string kScene = "simulate --body spheroid --a 20mm --b 32mm --theta 10deg --alpha 30deg ";

TEST(SimulateCli, JsonReproducesTheReferenceRelease) {
  const json& rel = testing::ReferenceCase("paper_fig4_b_over_a_1.6").at("outputs").at("release");
  const double x0 = rel.at("x0");
  std::ostringstream x0_text;
  x0_text.precision(17);
  x0_text << x0 << "m";
  const json& xt = rel.at("x_at_t");
  std::string times;
  for (const auto& p : xt) {
    if (!times.empty()) times += ',';
    times += std::to_string(p.at("t").get<double>());
    times += 's';
  }
  for (const char* method : {"quadrature", "ode"}) {
    const auto r = RunUphill(kScene + "--x0 " + x0_text.str() + " --at-times " + times + " --json --method " + method);
    ASSERT_EQ(r.status, 0) << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j.at("samples").size(), xt.size());
    for (size_t i = 0; i < xt.size(); ++i) {
      const json& s = j.at("samples")[i];
      for (const char* key : {"t", "x", "z", "v", "vx", "vz", "angle"}) EXPECT_TRUE(s.contains(key)) << key;
      const double ref = testing::RefValue(xt[i].at("x"));
      EXPECT_NEAR(s.at("x").get<double>(), ref, 1e-10 * ref) << method;
    }
    ASSERT_EQ(j.at("events").size(), 1u);
    EXPECT_EQ(j.at("events")[0].at("kind"), "falls off");
    const double t_max = testing::RefValue(rel.at("t_to_x_max"));
    EXPECT_NEAR(j.at("events")[0].at("t").get<double>(), t_max, 1e-10 * t_max);
    EXPECT_EQ(j.at("direction"), 1);
  }
}

TEST(SimulateCli, AtPositionsGivesTimesAndPositionEvents) {
  const auto r = RunUphill(kScene + "--x0 100mm --at-x 110mm,12cm --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j.at("samples").size(), 2u);
  EXPECT_NEAR(j.at("samples")[0].at("x").get<double>(), 0.11, 1e-12);
  EXPECT_NEAR(j.at("samples")[1].at("x").get<double>(), 0.12, 1e-12);
  EXPECT_GT(j.at("samples")[1].at("t").get<double>(), j.at("samples")[0].at("t").get<double>());
  ASSERT_EQ(j.at("events").size(), 3u);  // falls off, then the two positions
  EXPECT_EQ(j.at("events")[1].at("kind"), "position");
  EXPECT_EQ(j.at("events")[1].at("t"), j.at("samples")[0].at("t"));
}

TEST(SimulateCli, DtRunsToTheEndAndMillisecondsEqualSeconds) {
  const auto a = RunUphill(kScene + "--x0 120mm --dt 50ms --csv");
  const auto b = RunUphill(kScene + "--x0 0.12m --dt 0.05s --csv --g 9.80665m/s2");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out, b.out);
  EXPECT_EQ(a.out.substr(0, a.out.find('\n')), "t_s,x_m,z_m,v_m/s,vx_m/s,vz_m/s,angle_rad");
  // the last row is the fall-off
  const std::string last = a.out.substr(a.out.rfind('\n', a.out.size() - 2) + 1);
  EXPECT_NE(last.find(",0.1"), std::string::npos) << last;
}

TEST(SimulateCli, TableHasUnitsAndEvents) {
  const auto r = RunUphill(kScene + "--x0 80mm --v0 0.02m/s --at-times 0.1s");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("t [s]"), std::string::npos);
  EXPECT_NE(r.out.find("x [mm]"), std::string::npos);
  EXPECT_NE(r.out.find("turning point"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reaches O"), std::string::npos) << r.out;
}

TEST(SimulateCli, FrictionUsesTheOdeAndComesToRest) {
  const auto r = RunUphill(kScene + "--x0 80mm --v0 0.03m/s --mu 0.02 --dt 0.1s --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("method"), "ode");
  EXPECT_EQ(j.at("events").back().at("kind"), "comes to rest");
}

// A spheroid on round rods: both methods from rest agree; an initial speed or rolling resistance
// picks the ode method under --method auto.
TEST(SimulateCli, SpheroidOnRodsByBothMethods) {
  const std::string rods = "simulate --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 200mm "
                           "--rod-diameter 10mm ";
  std::vector<double> x_by_method;
  for (const char* method : {"quadrature", "ode"}) {
    const auto r = RunUphill(rods + "--x0 346mm --at-times 0.3s --json --method " + method);
    ASSERT_EQ(r.status, 0) << r.err;
    x_by_method.push_back(json::parse(r.out).at("samples").at(0).at("x").get<double>());
  }
  EXPECT_NEAR(x_by_method[0], x_by_method[1], 1e-12);
  const auto push = RunUphill(rods + "--x0 300mm --v0 0.05m/s --dt 0.1s --json");
  ASSERT_EQ(push.status, 0) << push.err;
  EXPECT_EQ(json::parse(push.out).at("method"), "ode");
  // Pushed from just below the rest band of μ = 0.01 ([344.18, 345.64] mm) with the speed that
  // stops it near the middle.
  const auto rest = RunUphill(rods + "--x0 344mm --v0 5.5mm/s --mu 0.01 --dt 0.1s --json");
  ASSERT_EQ(rest.status, 0) << rest.err;
  const json rest_event = json::parse(rest.out).at("events").back();
  EXPECT_EQ(rest_event.at("kind"), "comes to rest");
  EXPECT_GE(rest_event.at("x").get<double>(), 0.34417);
  EXPECT_LE(rest_event.at("x").get<double>(), 0.34565);
  const auto refused = RunUphill(rods + "--x0 300mm --v0 0.05m/s --dt 0.1s --method quadrature");
  EXPECT_EQ(refused.status, 2);
  EXPECT_EQ(refused.err.rfind("uphill: --v0:", 0), 0u) << refused.err;
}

TEST(SimulateCli, BadInputExitsTwoNamingTheFlag) {
  const auto expect_error = [](const std::string& args, const std::string& flag) {
    const auto r = RunUphill(kScene + args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(r.err.rfind("uphill: " + flag + ":", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  };
  expect_error("--at-times 1s", "--x0");
  expect_error("--x0 80 --at-times 1s", "--x0");
  expect_error("--x0 500mm --at-times 1s", "--x0");
  expect_error("--x0 80mm --at-times 1", "--at-times");
  expect_error("--x0 80mm --at-times 10s", "--at-times");
  expect_error("--x0 80mm", "--at-times/--at-x/--dt");
  expect_error("--x0 80mm --dt 1ms --at-x 70mm", "--at-times/--at-x/--dt");
  expect_error("--x0 80mm --at-x 100mm", "--at-x");
  expect_error("--x0 80mm --dt 1ms --v0 1", "--v0");
  expect_error("--x0 80mm --dt 1ms --g 9.81", "--g");
  expect_error("--x0 80mm --dt 1ms --mu 0.1 --method quadrature", "--method");
  expect_error("--x0 80mm --dt 1ms --method euler", "--method");
  // The cone rolling toward its apex never ends: --dt needs --t-end.
  const auto r = RunUphill("simulate --body double-cone --R 50mm --h 100mm --theta 5deg --alpha 60deg --x0 30mm --dt 10ms");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("uphill: --t-end:", 0), 0u) << r.err;
  const auto ok = RunUphill("simulate --body double-cone --R 50mm --h 100mm --theta 5deg --alpha 60deg --x0 30mm "
                            "--dt 10ms --t-end 0.1s --csv");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(std::count(ok.out.begin(), ok.out.end(), '\n'), 12);  // header + t = 0 … 0.1 s
}

}  // namespace
}  // namespace uphill::testing
