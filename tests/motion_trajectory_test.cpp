// The equation-of-motion method (MotionMethod::kOde) on the three trajectories of
// `uphill bench motion` (oracle/motion_problems.hpp: a release from rest, a throw toward O that
// turns and falls off, a throw with rolling resistance that comes to rest), against src/oracle's
// 50-digit references (oracle/motion_reference.hpp: the energy balance of each leg integrated by
// Gauss–Kronrod in cpp_bin_float_50, turning points located in 50 digits; it shares no code with
// src/motion). Checked: the first time at positions on every leg, the events (turning point,
// rest, fall-off) with their times and positions, x(t) back at the reference times, and that the
// accuracy follows the requested tolerance (motion.hpp). The new oracle is itself checked against
// the older, separately written release-time oracle (release_times_reference.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "oracle/motion_problems.hpp"
#include "oracle/release_times_reference.hpp"

namespace uphill::testing {
namespace {

using oracle::MotionProblem;
using oracle::MotionProblemKind;
using oracle::TrajectoryEventKind;

MotionOptions Ode(const MotionProblem& p, double tolerance = 1e-13) {
  MotionOptions o;
  o.method = MotionMethod::kOde;
  o.g = p.g;
  o.v0 = p.v0;
  o.mu = p.mu;
  o.tolerance = tolerance;
  return o;
}

double MaxRelError(const Motion& m, const MotionProblem& p) {
  double worst = 0;
  for (size_t i = 0; i < p.xs.size(); ++i)
    worst = std::max(worst, std::abs(m.TimeAt(p.xs[i]) / p.reference.times[i] - 1));
  return worst;
}

// Accuracy promised at the default tolerance (motion.hpp): 1e-10 relative.
constexpr double kRel = 1e-10;

TEST(MotionTrajectory, OracleAgreesWithTheReleaseTimeOracle) {
  const MotionProblem p = oracle::MakeMotionProblem(MotionProblemKind::kRelease, 6);
  const Rails& r = p.scene.rails();
  const std::vector<double> other =
      oracle::SpheroidReleaseTimes(p.a, p.b, r.tan_theta, r.tan_half_alpha, p.g, p.x0, p.xs);
  for (size_t i = 0; i < p.xs.size(); ++i) EXPECT_NEAR(p.reference.times[i], other[i], 1e-15 * other[i]);
}

TEST(MotionTrajectory, TurnsAndFallsOffAsTheReference) {
  const MotionProblem p = oracle::MakeMotionProblem(MotionProblemKind::kTurning, 16);
  const auto& ref = p.reference;
  ASSERT_EQ(ref.events.size(), 2u);
  ASSERT_EQ(ref.events[0].kind, TrajectoryEventKind::kTurningPoint);
  ASSERT_EQ(ref.events[1].kind, TrajectoryEventKind::kFallOff);
  const Motion m(p.scene, p.x0, Ode(p));
  EXPECT_EQ(m.direction(), -1);
  ASSERT_EQ(m.events().size(), 2u);
  EXPECT_EQ(m.events()[0].kind, MotionEventKind::kTurningPoint);
  EXPECT_NEAR(m.events()[0].t, ref.events[0].t, kRel * ref.events[0].t);
  EXPECT_NEAR(m.events()[0].x, ref.events[0].x, kRel * ref.events[0].x);
  EXPECT_EQ(m.events()[1].kind, MotionEventKind::kFallOff);
  EXPECT_NEAR(m.end_time(), ref.events[1].t, kRel * ref.events[1].t);
  for (size_t i = 0; i < p.xs.size(); ++i)
    EXPECT_NEAR(m.TimeAt(p.xs[i]), ref.times[i], kRel * ref.times[i]) << "x = " << p.xs[i];
  for (size_t i = 0; i < p.xs.size(); ++i)
    EXPECT_NEAR(m.At(ref.times[i]).x, p.xs[i], kRel * p.xs[i]) << "t = " << ref.times[i];
  // Below the turning point: never.
  EXPECT_EQ(m.TimeAt(0.5 * (ref.events[0].x + *p.scene.x_eq())), std::numeric_limits<double>::infinity());
}

TEST(MotionTrajectory, ComesToRestAsTheReference) {
  const MotionProblem p = oracle::MakeMotionProblem(MotionProblemKind::kComesToRest, 12);
  const auto& ref = p.reference;
  ASSERT_EQ(ref.events.size(), 1u);
  ASSERT_EQ(ref.events[0].kind, TrajectoryEventKind::kRest);
  // The rest point lies in the rest band [x_rest(−μ), x_rest(μ)] (closed form, Scene::Rest).
  EXPECT_GT(ref.events[0].x, p.scene.Rest(p.mu)->low);
  EXPECT_LT(ref.events[0].x, p.scene.Rest(p.mu)->high);
  const Motion m(p.scene, p.x0, Ode(p));
  ASSERT_EQ(m.events().size(), 1u);
  EXPECT_EQ(m.events()[0].kind, MotionEventKind::kRest);
  EXPECT_NEAR(m.events()[0].t, ref.events[0].t, kRel * ref.events[0].t);
  EXPECT_NEAR(m.events()[0].x, ref.events[0].x, kRel * ref.events[0].x);
  // From the rest event on, the state is the rest point.
  EXPECT_NEAR(m.At(2 * ref.events[0].t).x, ref.events[0].x, kRel * ref.events[0].x);
  EXPECT_EQ(m.At(2 * ref.events[0].t).v, 0.0);
  for (size_t i = 0; i < p.xs.size(); ++i)
    EXPECT_NEAR(m.TimeAt(p.xs[i]), ref.times[i], kRel * ref.times[i]) << "x = " << p.xs[i];
  EXPECT_EQ(m.TimeAt(0.5 * (ref.events[0].x + *p.scene.x_eq())), std::numeric_limits<double>::infinity());
}

// The accuracy follows the tolerance: the largest relative error of the times stays below the
// requested tolerance (measured: 0.2–0.3 of it; the global error of Dormand–Prince 5(4) with its
// 4th-order dense output is not bounded by the per-step control, hence a margin of 10).
TEST(MotionTrajectory, ErrorFollowsTheTolerance) {
  for (MotionProblemKind kind : {MotionProblemKind::kRelease, MotionProblemKind::kTurning,
                                 MotionProblemKind::kComesToRest}) {
    const MotionProblem p = oracle::MakeMotionProblem(kind, 10);
    for (double tolerance : {1e-6, 1e-9, 1e-12}) {
      const double error = MaxRelError(Motion(p.scene, p.x0, Ode(p, tolerance)), p);
      EXPECT_LE(error, 10 * tolerance) << p.name << ", tolerance " << tolerance;
      EXPECT_GT(error, 0.0) << p.name;  // the reference is not the code under test's own output
    }
  }
}

}  // namespace
}  // namespace uphill::testing
