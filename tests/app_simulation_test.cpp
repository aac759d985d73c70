// The simulation use case (src/app/simulation.hpp): sampling by times, by positions and by a step,
// its stable JSON, and errors that name the option. Truth: the release of
// paper_fig4_b_over_a_1.6 in the 60-digit reference (x at given t, t at given x, t to x_max).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "app/simulation.hpp"
#include "model/input_error.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

const nlohmann::json& Release() {
  return ReferenceCase("paper_fig4_b_over_a_1.6").at("outputs").at("release");
}

Scene ReleaseScene() { return CaseScene(ReferenceCase("paper_fig4_b_over_a_1.6")); }

TEST(Simulate, TimesAndPositionsAgreeWithTheReferenceRelease) {
  for (SimulationMethod method : {SimulationMethod::kQuadrature, SimulationMethod::kOde}) {
    SimulationRequest by_time;
    by_time.x0 = Release().at("x0");
    by_time.method = method;
    for (const auto& p : Release().at("x_at_t")) by_time.at_times.push_back(p.at("t"));
    const Simulation s = Simulate(ReleaseScene(), by_time);
    ASSERT_EQ(s.samples.size(), Release().at("x_at_t").size());
    for (std::size_t i = 0; i < s.samples.size(); ++i) {
      const double ref = RefValue(Release().at("x_at_t")[i].at("x"));
      EXPECT_NEAR(s.samples[i].x, ref, 1e-10 * ref);
    }
    ASSERT_EQ(s.events.size(), 1u);
    EXPECT_EQ(s.events[0].kind, MotionEventKind::kFallOff);
    const double t_max = RefValue(Release().at("t_to_x_max"));
    EXPECT_NEAR(s.events[0].t, t_max, 1e-10 * t_max);

    SimulationRequest by_position = by_time;
    by_position.at_times.clear();
    for (const auto& p : Release().at("t_at_x")) by_position.at_x.push_back(p.at("x"));
    const Simulation q = Simulate(ReleaseScene(), by_position);
    ASSERT_EQ(q.samples.size(), by_position.at_x.size());
    for (std::size_t i = 0; i < q.samples.size(); ++i) {
      const double ref = RefValue(Release().at("t_at_x")[i].at("t"));
      EXPECT_NEAR(q.samples[i].t, ref, 1e-10 * ref);
    }
  }
}

TEST(Simulate, StepSamplingEndsAtTheFallOffAndTheJsonCarriesEveryNumber) {
  SimulationRequest r;
  r.x0 = Release().at("x0");
  r.dt = 0.1;
  const Simulation s = Simulate(ReleaseScene(), r);
  const double t_max = RefValue(Release().at("t_to_x_max"));
  ASSERT_EQ(s.samples.size(), 10u);  // t = 0, 0.1, … 0.8, then the fall-off at 0.846 s
  EXPECT_EQ(s.samples.front().t, 0.0);
  EXPECT_NEAR(s.samples.back().t, t_max, 1e-10 * t_max);
  EXPECT_EQ(s.options.method, MotionMethod::kQuadrature);  // auto: no friction, released at rest
  // Round trip through the JSON text: every number comes back to the bit.
  const nlohmann::json j = nlohmann::json::parse(ToJson(s).dump());
  EXPECT_EQ(j.at("x0").get<double>(), s.x0);
  EXPECT_EQ(j.at("method"), "quadrature");
  EXPECT_EQ(j.at("direction"), 1);
  EXPECT_EQ(j.at("x_eq").get<double>(), *s.x_eq);
  EXPECT_EQ(j.at("x_max").get<double>(), s.x_max);
  ASSERT_EQ(j.at("samples").size(), s.samples.size());
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    EXPECT_EQ(j.at("samples")[i].at("t").get<double>(), s.samples[i].t);
    EXPECT_EQ(j.at("samples")[i].at("x").get<double>(), s.samples[i].x);
    EXPECT_EQ(j.at("samples")[i].at("vz").get<double>(), s.samples[i].vz);
  }
  EXPECT_EQ(j.at("events")[0].at("kind"), "falls off");
}

TEST(Simulate, ErrorsNameTheOption) {
  const auto error = [](SimulationRequest r) {
    try {
      Simulate(ReleaseScene(), r);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  SimulationRequest r;
  r.x0 = Release().at("x0");
  EXPECT_EQ(error(r), "--at-times/--at-x/--dt: give exactly one of them");
  r.at_times = {5.0};
  EXPECT_EQ(error(r).rfind("--at-times: 5 s is after the end of the motion (the motion ends at t = ", 0), 0u);
  r.mu = 0.01;
  r.method = SimulationMethod::kQuadrature;
  EXPECT_EQ(error(r), "--method: quadrature needs --mu 0 (energy conservation); use ode");
  r.method = SimulationMethod::kAuto;
  r.x0 = -1.0;
  EXPECT_EQ(error(r).rfind("--x0: ", 0), 0u);
}

// Issue 11: `simulate --method ode --v0 1e20m/s` failed with an internal error from a root solver
// (then a NaN end time in the message); --v0 1e300 m/s printed v = inf. The contract
// (app/simulation.hpp: |v0| <= kFastestV0, g in (0, kLargestG], mu in [0, kLargestMu]) is the
// truth: outside it, an InputError naming the flag and no number that is not finite; at its edge,
// a finite answer.
TEST(Simulate, RefusesSpeedsAndAccelerationsBeyondTheApparatus) {
  SimulationRequest r;
  r.x0 = Release().at("x0");
  r.at_times = {0.0};
  const auto error = [&](SimulationRequest q) {
    try {
      Simulate(ReleaseScene(), q);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const double v0 : {1e20, -1e20, 1e300, kFastestV0 * 1.01, std::numeric_limits<double>::infinity(),
                          std::numeric_limits<double>::quiet_NaN()}) {
    for (const SimulationMethod method : {SimulationMethod::kOde, SimulationMethod::kAuto}) {
      SimulationRequest q = r;
      q.v0 = v0;
      q.method = method;
      const std::string e = error(q);
      EXPECT_EQ(e.rfind("--v0: must be at most 1000 m/s in size", 0), 0u) << v0 << ": " << e;
    }
  }
  for (const double g : {0.0, -1.0, 1e300, std::numeric_limits<double>::quiet_NaN()}) {
    SimulationRequest q = r;
    q.g = g;
    EXPECT_EQ(error(q).rfind("--g: ", 0), 0u) << g;
  }
  SimulationRequest q = r;
  q.mu = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error(q).rfind("--mu: ", 0), 0u);
  // At the edge the motion still answers in finite numbers.
  q = r;
  q.v0 = kFastestV0;
  q.method = SimulationMethod::kOde;
  const Simulation s = Simulate(ReleaseScene(), q);
  ASSERT_EQ(s.samples.size(), 1u);
  EXPECT_TRUE(std::isfinite(s.samples[0].v));
  EXPECT_TRUE(std::isfinite(s.samples[0].x));
}

}  // namespace
}  // namespace uphill::testing
