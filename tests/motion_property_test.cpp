// Properties of src/motion beyond the reference values: energy conservation, time reversal,
// agreement of the two methods, the hard cases (release within 1e-9 of X, the fall-off,
// θ = 0, α → 0, micrometre to kilometre bodies, the double cone), initial speed and turning
// points, rolling resistance, directions, and the input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "model/input_error.hpp"
#include "model/scene.hpp"
#include "motion/motion.hpp"

namespace uphill::testing {
namespace {

constexpr double kDeg = M_PI / 180.0;

Scene Spheroid(double a, double b, double theta_deg, double alpha_deg, double rod = 0.0) {
  return Scene(Body::Spheroid(a, b), Rails::FromAngles(theta_deg * kDeg, alpha_deg * kDeg), rod);
}
MotionOptions Ode(double v0 = 0.0, double mu = 0.0) {
  MotionOptions o;
  o.method = MotionMethod::kOde;
  o.v0 = v0;
  o.mu = mu;
  return o;
}
MotionOptions Quad(double v0 = 0.0) {
  MotionOptions o;
  o.v0 = v0;
  return o;
}

// ½·K·v² + g·z − g·z0 relative to g·z0 along the trajectory (μ = 0, from rest).
double MaxEnergyError(const Motion& m, double t_end, double g = 9.80665) {
  const Scene& s = m.scene();
  const double z0 = s.At(m.x0()).z;
  double worst = 0;
  for (int i = 0; i <= 40; ++i) {
    const MotionSample p = m.At(t_end * i / 40.0);
    const double e = 0.5 * s.KineticFactor(p.x) * p.v * p.v + g * (p.z - z0);
    worst = std::max(worst, std::abs(e) / (g * z0));
  }
  return worst;
}

TEST(MotionEnergy, ConservedByBothMethods) {
  const Scene s = Spheroid(0.02, 0.032, 1.0, 30.0);
  const double x0 = 1.05 * *s.x_eq();
  for (const MotionOptions& o : {Quad(), Ode()}) {
    const Motion m(s, x0, o);
    EXPECT_LT(MaxEnergyError(m, 0.999 * m.end_time()), 1e-12);
  }
}

TEST(MotionEnergy, SamplesAreConsistent) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  const Motion m(s, 1.2 * *s.x_eq());
  const MotionSample p = m.At(0.5 * m.end_time());
  EXPECT_NEAR(std::hypot(p.vx, p.vz), p.v, 1e-14 * p.v);
  EXPECT_NEAR(p.vz / p.vx, s.At(p.x).dzdx, 1e-12 * std::abs(p.vz / p.vx));
  EXPECT_GT(p.vx, 0.0);
  EXPECT_GT(p.angle, 0.0);
  EXPECT_DOUBLE_EQ(s.At(p.x).z, p.z);
}

TEST(MotionMethods, AgreeOnPositionsSpeedsAndAngles) {
  for (const Scene& s : {Spheroid(0.02, 0.032, 1.0, 30.0), Spheroid(0.015875, 0.0254, 14.0, 9.8),
                         Scene(Body::Sphere(0.02), Rails::FromAngles(0.0, 120 * kDeg)),
                         Scene(Body::Sphere(0.02), Rails::FromAngles(10 * kDeg, 30 * kDeg), 0.005)}) {
    const double X = *s.x_eq();
    const double x0 = X + 0.1 * (s.x_max() - X);
    const Motion q(s, x0, Quad()), o(s, x0, Ode());
    EXPECT_NEAR(q.end_time(), o.end_time(), 1e-11 * q.end_time());
    for (int i = 1; i < 10; ++i) {
      const double t = q.end_time() * i / 10.0;
      const MotionSample a = q.At(t), b = o.At(t);
      EXPECT_NEAR(a.x, b.x, 1e-11 * a.x) << t;
      EXPECT_NEAR(a.v, b.v, 1e-9 * a.v) << t;
      EXPECT_NEAR(a.angle, b.angle, 1e-9 * std::abs(a.angle)) << t;
    }
  }
}

TEST(MotionReversal, ReversedStateReturnsToTheStart) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  const double x0 = 1.3 * *s.x_eq();
  const Motion m(s, x0);
  const double t1 = 0.6 * m.end_time();
  const MotionSample p = m.At(t1);
  for (const MotionOptions& o : {Quad(-p.v), Ode(-p.v)}) {
    const Motion back(s, p.x, o);
    ASSERT_FALSE(back.events().empty());
    const MotionEvent turn = back.events().front();
    EXPECT_EQ(turn.kind, MotionEventKind::kTurningPoint);
    EXPECT_NEAR(turn.t, t1, 1e-11 * t1);
    EXPECT_NEAR(turn.x, x0, 1e-11 * x0);
    EXPECT_NEAR(back.At(t1).x, x0, 1e-11 * x0);
    // and after the turn it retraces the forward motion
    EXPECT_NEAR(back.At(t1 + 0.5 * t1).x, m.At(0.5 * t1).x, 1e-11 * x0);
  }
}

TEST(MotionHardCases, ReleaseWithin1e9OfX) {
  const Scene s = Spheroid(0.025, 0.04, 10.0, 30.0);
  const double X = *s.x_eq();
  const double x0 = X + 1e-9;
  const Motion q(s, x0, Quad()), o(s, x0, Ode());
  const double t_end = q.end_time();
  EXPECT_NEAR(o.end_time(), t_end, 1e-9 * t_end);
  // Escape time ~ ln(1/(x0 − X))/λ: compare with a release 1e-7 from X: Δt = ln(100)/λ.
  const Motion q7(s, X + 1e-7, Quad());
  const double z2 = std::abs((s.At(X + 1e-6).dzdx - s.At(X - 1e-6).dzdx) / 2e-6);
  const double lambda = std::sqrt(9.80665 * z2 / s.KineticFactor(X));
  EXPECT_NEAR(t_end - q7.end_time(), std::log(100.0) / lambda, 1e-5 * t_end);
  const double x_half = X + 0.5 * (s.x_max() - X);
  EXPECT_NEAR(q.TimeAt(x_half), o.TimeAt(x_half), 1e-9 * t_end);
  EXPECT_NEAR(q.At(0.9 * t_end).x, o.At(0.9 * t_end).x, 1e-9 * X);
}

TEST(MotionHardCases, ReachesTheFallOffInFiniteTime) {
  const Scene s = Spheroid(0.02, 0.032, 5.0, 30.0);
  const Motion q(s, 1.5 * *s.x_eq());
  ASSERT_EQ(q.events().size(), 1u);
  EXPECT_EQ(q.events()[0].kind, MotionEventKind::kFallOff);
  EXPECT_EQ(q.events()[0].x, s.x_max());
  const MotionSample end = q.At(q.end_time());
  EXPECT_NEAR(end.x, s.x_max(), 1e-14 * s.x_max());
  EXPECT_NEAR(end.vx, 0.0, 1e-6 * end.v);  // the path is vertical there
  EXPECT_LT(end.vz, 0.0);
  EXPECT_TRUE(std::isfinite(q.TimeAt(s.x_max())));
  EXPECT_THROW(q.At(1.01 * q.end_time()), InputError);
  EXPECT_EQ(q.TimeAt(s.x_max() * 1.0000001), std::numeric_limits<double>::infinity());
}

TEST(MotionHardCases, ThetaZeroAndTinyAlpha) {
  const Scene flat(Body::Sphere(0.02), Rails::FromAngles(0.0, 120 * kDeg));
  EXPECT_EQ(Motion(flat, 0.0).direction(), 0);
  EXPECT_EQ(Motion(flat, 0.0, Ode()).direction(), 0);
  const Scene narrow = Spheroid(0.02, 0.032, 10.0, 1e-4 / kDeg);  // α = 1e-4 rad
  const double X = *narrow.x_eq();
  const double x0 = X + 0.05 * *narrow.FallOffMargin();
  const Motion q(narrow, x0, Quad()), o(narrow, x0, Ode());
  EXPECT_NEAR(q.end_time(), o.end_time(), 1e-10 * q.end_time());
  EXPECT_LT(MaxEnergyError(q, 0.99 * q.end_time()), 1e-12);
}

TEST(MotionHardCases, ScalesFromMicrometresToKilometres) {
  // Same shape scaled by k: times scale by sqrt(k).
  const Scene unit = Spheroid(0.02, 0.032, 10.0, 30.0);
  const double x0 = 1.2 * *unit.x_eq();
  const Motion ref(unit, x0);
  for (double k : {5e-5, 5e4}) {
    const Scene scaled = Spheroid(0.02 * k, 0.032 * k, 10.0, 30.0);
    for (const MotionOptions& o : {Quad(), Ode()}) {
      const Motion m(scaled, x0 * k, o);
      EXPECT_NEAR(m.end_time() / std::sqrt(k), ref.end_time(), 1e-11 * ref.end_time()) << k;
      const double t = 0.7 * m.end_time();
      EXPECT_NEAR(m.At(t).x / k, ref.At(0.7 * ref.end_time()).x, 1e-11 * x0) << k;
    }
  }
}

TEST(MotionCone, RollsTowardTheApexForever) {
  const Scene cone(Body::DoubleCone(0.05, 0.1), Rails::FromAngles(5 * kDeg, 60 * kDeg));
  const double x0 = cone.x_low() + 0.05 * (cone.x_max() - cone.x_low());
  const Motion q(cone, x0, Quad()), o(cone, x0, Ode());
  EXPECT_EQ(q.direction(), 1);
  EXPECT_TRUE(q.events().empty());
  EXPECT_EQ(q.end_time(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(q.TimeAt(cone.x_max()), std::numeric_limits<double>::infinity());
  // Logarithmic divergence: each factor 10 closer to the apex adds about the same time.
  const double xf = cone.x_max();
  const double t3 = q.TimeAt(xf - 1e-3 * (xf - x0)), t4 = q.TimeAt(xf - 1e-4 * (xf - x0)),
               t5 = q.TimeAt(xf - 1e-5 * (xf - x0));
  EXPECT_NEAR(t5 - t4, t4 - t3, 1e-3 * (t4 - t3));
  EXPECT_NEAR(o.TimeAt(xf - 1e-4 * (xf - x0)), t4, 1e-10 * t4);
  EXPECT_NEAR(q.At(t4).x, xf - 1e-4 * (xf - x0), 1e-12 * xf);
  // rolling down (θ > θ0): toward O
  const Scene down(Body::DoubleCone(0.05, 0.1), Rails::FromAngles(20 * kDeg, 60 * kDeg));
  const double xd = down.x_low() + 0.5 * (down.x_max() - down.x_low());
  const Motion d(down, xd, Quad()), dd(down, xd, Ode());
  EXPECT_EQ(d.direction(), -1);
  ASSERT_EQ(d.events().size(), 1u);
  EXPECT_EQ(d.events()[0].kind, MotionEventKind::kReachesO);
  EXPECT_NEAR(dd.end_time(), d.end_time(), 1e-11 * d.end_time());
}

TEST(MotionDirection, BelowXRollsBackToO) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  const double X = *s.x_eq();
  for (const MotionOptions& o : {Quad(), Ode()}) {
    const Motion m(s, 0.8 * X, o);
    EXPECT_EQ(m.direction(), -1);
    ASSERT_EQ(m.events().size(), 1u);
    EXPECT_EQ(m.events()[0].kind, MotionEventKind::kReachesO);
    EXPECT_EQ(m.events()[0].x, s.x_low());
    EXPECT_LT(m.At(0.5 * m.end_time()).vx, 0.0);
    EXPECT_EQ(Motion(s, X, o).direction(), 0);
    EXPECT_EQ(Motion(s, X, o).At(3.0).x, X);
  }
  const Motion q(s, 0.8 * X), o(s, 0.8 * X, Ode());
  EXPECT_NEAR(q.end_time(), o.end_time(), 1e-11 * q.end_time());
}

TEST(MotionInitialSpeed, TurningPointAndOverTheTop) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  const double X = *s.x_eq();
  const double x0 = 0.8 * X;
  // Toward X with too little energy: turns, then rolls back to O.
  const double v_small = 0.01;
  const Motion q(s, x0, Quad(v_small)), o(s, x0, Ode(v_small));
  ASSERT_EQ(q.events().size(), 2u);
  ASSERT_EQ(o.events().size(), 2u);
  EXPECT_EQ(q.events()[0].kind, MotionEventKind::kTurningPoint);
  EXPECT_NEAR(q.events()[0].t, o.events()[0].t, 1e-10 * q.events()[0].t);
  EXPECT_NEAR(q.events()[0].x, o.events()[0].x, 1e-12 * X);
  const double z_turn = s.At(x0).z + s.KineticFactor(x0) * v_small * v_small / (2 * 9.80665);
  EXPECT_NEAR(s.At(q.events()[0].x).z, z_turn, 1e-13 * z_turn);
  EXPECT_NEAR(q.end_time(), o.end_time(), 1e-10 * q.end_time());
  // Enough energy: over the top, then falls off beyond X.
  const Motion over(s, x0, Quad(0.2)), over_o(s, x0, Ode(0.2));
  ASSERT_EQ(over.events().size(), 1u);
  EXPECT_EQ(over.events()[0].kind, MotionEventKind::kFallOff);
  EXPECT_NEAR(over.end_time(), over_o.end_time(), 1e-10 * over.end_time());
  EXPECT_NEAR(over.TimeAt(X), over_o.TimeAt(X), 1e-10 * over.end_time());
}

TEST(MotionFriction, ComesToRestInTheRestBand) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  const double mu = 0.02;
  const RestBand band = *s.Rest(mu);
  // Released at rest inside the band: stays.
  const Motion stay(s, 0.5 * (band.low + band.high), Ode(0.0, mu));
  EXPECT_EQ(stay.direction(), 0);
  ASSERT_EQ(stay.events().size(), 1u);
  EXPECT_EQ(stay.events()[0].kind, MotionEventKind::kRest);
  // Pushed toward X from below: stops at a turning point inside the band.
  const double x0 = band.low - 0.2 * (band.high - band.low);
  const Motion m(s, x0, Ode(0.05, mu));
  ASSERT_FALSE(m.events().empty());
  const MotionEvent rest = m.events().back();
  EXPECT_EQ(rest.kind, MotionEventKind::kRest);
  EXPECT_GE(rest.x, band.low);
  EXPECT_LE(rest.x, band.high);
  // Energy balance with the work of the resistance: ½K v² + g z + g μ |Δx| = const.
  const double g = 9.80665, z0 = s.At(x0).z, k0 = s.KineticFactor(x0);
  const double e0 = 0.5 * k0 * 0.05 * 0.05;
  for (double f : {0.3, 0.7}) {
    const MotionSample p = m.At(f * rest.t);
    const double e = 0.5 * s.KineticFactor(p.x) * p.v * p.v + g * (p.z - z0) + g * mu * (p.x - x0);
    EXPECT_NEAR(e, e0, 1e-11 * e0);
  }
  EXPECT_EQ(m.At(2 * rest.t).x, m.At(rest.t).x);
  EXPECT_NEAR(m.At(rest.t).v, 0.0, 1e-12);
  // Beyond X with friction it still rolls up and falls off.
  const Motion up(s, band.high + 0.01 * *s.FallOffMargin(), Ode(0.0, mu));
  EXPECT_EQ(up.events().back().kind, MotionEventKind::kFallOff);
}

Scene LabSpheroidOnRods() {
  return Scene(Body::Spheroid(0.015875, 0.0254), Rails::FromApparatus(1.165, 0.3, 0.2, LConvention::kHorizontal),
               0.005);
}

// The normal-angle path the motion of a spheroid on rods uses: consistent with the solved path,
// X in closed form, and derivatives that match difference quotients of the values.
TEST(MotionRods, NormalAnglePathIsConsistent) {
  const SpheroidOnRods p(0.015875, 0.0254, 0.3 / 1.165, 0.1 / 1.165, 0.005);
  const SpheroidOnRods::NormalAnglePoint eq = p.PathAtNormalAngle(p.NormalAngleAtEquilibrium());
  EXPECT_NEAR(eq.x, p.x_eq(), 1e-15);
  EXPECT_NEAR(eq.z, p.z_eq(), 1e-15);
  EXPECT_NEAR(eq.dz, 0.0, 1e-15);
  for (double f : {0.0, 0.2, 0.5, 0.9}) {
    const double beta = f * p.normal_angle_low(), h = 1e-5;
    const auto c = p.PathAtNormalAngle(beta), lo = p.PathAtNormalAngle(beta - h), hi = p.PathAtNormalAngle(beta + h);
    double x, z;
    p.CentreAtNormalAngle(beta, &x, &z);
    EXPECT_NEAR(c.x, x, 1e-15);
    EXPECT_NEAR(c.z, z, 1e-15);
    EXPECT_NEAR(c.dx, (hi.x - lo.x) / (2 * h), 1e-9);
    EXPECT_NEAR(c.dz, (hi.z - lo.z) / (2 * h), 1e-9);
    EXPECT_NEAR(c.ddx, (hi.dx - lo.dx) / (2 * h), 1e-9);
    EXPECT_NEAR(c.ddz, (hi.dz - lo.dz) / (2 * h), 1e-9);
    EXPECT_NEAR(c.dr_star, (hi.r_star - lo.r_star) / (2 * h), 1e-9);
    if (f > 0) {
      EXPECT_NEAR(p.NormalAngleOf(c.x), beta, 1e-12);
    }
  }
}

// A spheroid with a = b on rods is a sphere on rods: numeric normal-angle path against the closed
// form of a sphere of radius R + r, by both methods.
TEST(MotionRods, SphereOnRodsMatchesTheNumericPathOfAnEqualAxesSpheroid) {
  const Rails r = Rails::FromApparatus(1.165, 0.3, 0.2, LConvention::kHorizontal);
  const Scene sphere(Body::Sphere(0.02), r, 0.005), spheroid(Body::Spheroid(0.02, 0.02), r, 0.005);
  const double X = *sphere.x_eq();
  const double x0 = X + 0.05 * (sphere.x_max() - X);
  const Motion ref(sphere, x0);
  for (const MotionOptions& o : {Quad(), Ode()}) {
    const Motion m(spheroid, x0, o);
    for (double f : {0.01, 0.3, 0.9, 1.0}) {
      const double x = x0 + f * (sphere.x_max() - x0);
      EXPECT_NEAR(m.TimeAt(x), ref.TimeAt(x), 1e-11 * ref.TimeAt(x)) << f;
    }
    EXPECT_NEAR(m.end_time(), ref.end_time(), 1e-11 * ref.end_time());
  }
}

// Both methods on the lab spheroid on rods, rolling up (beyond X) and back to O (below X):
// they agree, and energy is conserved.
TEST(MotionRods, MethodsAgreeAndConserveEnergy) {
  const Scene s = LabSpheroidOnRods();
  const double X = *s.x_eq();
  for (double x0 : {X + 0.2 * (s.x_max() - X), X - 0.3 * (X - s.x_low()), X + 1e-6 * (s.x_max() - X)}) {
    const Motion q(s, x0, Quad()), o(s, x0, Ode());
    EXPECT_EQ(q.direction(), o.direction());
    EXPECT_NEAR(q.end_time(), o.end_time(), 1e-10 * q.end_time()) << x0;
    const double end = q.direction() > 0 ? s.x_max() : s.x_low();
    for (double f : {0.05, 0.5, 0.95}) {
      const double x = x0 + f * (end - x0);
      EXPECT_NEAR(q.TimeAt(x), o.TimeAt(x), 1e-10 * q.TimeAt(x)) << x0 << " " << f;
      const double t = q.TimeAt(x);
      EXPECT_NEAR(o.At(t).x, x, 1e-9 * std::abs(end - x0));
    }
    EXPECT_LT(MaxEnergyError(q, 0.999 * q.end_time()), 1e-12) << x0;
    EXPECT_LT(MaxEnergyError(o, 0.999 * o.end_time()), 1e-12) << x0;
  }
}

// Initial speed and rolling resistance on rods (ode): a push toward X from below turns back
// (energy conserved); with μ > 0 the body stops inside the rest band of Scene::Rest(μ), with the
// resistance's work accounted for; the quadrature refuses both with a clear message.
TEST(MotionRods, InitialSpeedAndRollingResistance) {
  const Scene s = LabSpheroidOnRods();
  const double X = *s.x_eq(), g = 9.80665;
  const double x0 = X - 0.2 * (X - s.x_low());
  const Motion push(s, x0, Ode(0.01));
  ASSERT_GE(push.events().size(), 2u);
  EXPECT_EQ(push.events()[0].kind, MotionEventKind::kTurningPoint);
  EXPECT_LT(push.events()[0].x, X);
  EXPECT_EQ(push.events().back().kind, MotionEventKind::kReachesO);
  const double z0 = s.At(x0).z, e0 = 0.5 * s.KineticFactor(x0) * 0.01 * 0.01;
  for (double f : {0.2, 0.6, 0.95}) {
    const MotionSample p = push.At(f * push.end_time());
    EXPECT_NEAR(0.5 * s.KineticFactor(p.x) * p.v * p.v + g * (p.z - z0), e0, 1e-12 * g * z0) << f;
  }
  EXPECT_THROW(Motion(s, x0, Quad(0.01)), InputError);

  const double mu = 0.01;
  const RestBand band = *s.Rest(mu);
  ASSERT_LT(band.low, band.high);
  const double x1 = band.low - 0.3 * (band.high - band.low), x_mid = 0.5 * (band.low + band.high);
  // The speed that the energy balance says brings it to rest at the band's middle.
  const double v1 = std::sqrt(2.0 * g * (s.At(x_mid).z - s.At(x1).z + mu * (x_mid - x1)) / s.KineticFactor(x1));
  const Motion m(s, x1, Ode(v1, mu));
  ASSERT_FALSE(m.events().empty());
  const MotionEvent rest = m.events().back();
  EXPECT_EQ(rest.kind, MotionEventKind::kRest);
  EXPECT_GE(rest.x, band.low);
  EXPECT_LE(rest.x, band.high);
  const double z1 = s.At(x1).z, e1 = 0.5 * s.KineticFactor(x1) * v1 * v1;
  for (double f : {0.3, 0.7}) {  // monotone in x until the rest: work g·μ·(x − x1)
    const MotionSample p = m.At(f * rest.t);
    EXPECT_NEAR(0.5 * s.KineticFactor(p.x) * p.v * p.v + g * (p.z - z1) + g * mu * (p.x - x1), e1, 1e-11 * e1);
  }
  const Motion stay(s, 0.5 * (band.low + band.high), Ode(0.0, mu));
  EXPECT_EQ(stay.direction(), 0);
  MotionOptions quad_mu = Quad();
  quad_mu.mu = mu;
  EXPECT_THROW(Motion(s, x1, quad_mu), InputError);
}

// Release trajectories for ReleaseTimes: n positions equally spaced from x0 to end.
std::vector<double> Positions(double x0, double end, int n) {
  std::vector<double> xs;
  for (int i = 1; i <= n; ++i) xs.push_back(i == n ? end : x0 + (end - x0) * i / n);
  return xs;
}
double MaxRelativeDifference(const std::vector<double>& t, const Motion& m, const std::vector<double>& xs) {
  double worst = 0;
  for (size_t i = 0; i < xs.size(); ++i) worst = std::max(worst, std::abs(t[i] / m.TimeAt(xs[i]) - 1));
  return worst;
}

TEST(MotionReleaseTimes, FixedGaussTrajectoryMatchesTheAdaptiveQuadrature) {
  const Scene s = Spheroid(0.02, 0.032, 1.0, 30.0);
  const double x0 = 1.05 * *s.x_eq();
  const std::vector<double> xs = Positions(x0, 0.99 * s.x_max(), 200);
  ReleaseTimesOptions o;
  o.nodes = 8;
  const Motion m(s, x0);
  EXPECT_LT(MaxRelativeDifference(ReleaseTimes(s, x0, xs, o), m, xs), 2e-14);
}

// The a-priori node count meets the tolerance (within a factor 3 at 1e-13, where the reference's
// own error of a few 1e-15 counts) on releases from 1 + 1e-6 to 3 X, few and many positions,
// up to x_max itself, for spheroids and a sphere on rods, with every kernel available.
TEST(MotionReleaseTimes, APrioriNodeCountMeetsTheTolerance) {
  struct Case {
    Scene scene;
    double release;  // x0/X
    double end;      // last position / x_max
    int n;
  };
  const std::vector<Case> cases = {
      {Spheroid(0.02, 0.032, 1.0, 30.0), 1.05, 0.99, 200},
      {Spheroid(0.02, 0.02, 10.0, 60.0), 1.0 + 1e-6, 1.0, 20},
      {Spheroid(0.02, 0.01, 0.01, 90.0), 3.0, 0.999, 50},
      {Spheroid(0.0158, 0.0254, 5.0, 20.0), 1.2, 1.0, 3},
      {Scene(Body::Sphere(0.02), Rails::FromAngles(2 * kDeg, 40 * kDeg), 0.004), 1.5, 0.9, 100},
  };
  for (const Case& c : cases) {
    const double x0 = c.release * *c.scene.x_eq();
    const std::vector<double> xs = Positions(x0, c.end * c.scene.x_max(), c.n);
    MotionOptions mo;
    mo.tolerance = 1e-15;
    const Motion m(c.scene, x0, mo);
    for (VectorKernel kernel : {VectorKernel::kScalar, VectorKernel::kAvx2}) {
      if (!VectorKernelAvailable(kernel)) continue;
      for (double tol : {1e-4, 1e-8, 1e-11, 1e-13}) {
        ReleaseTimesOptions o;
        o.tolerance = tol;
        o.kernel = kernel;
        const double err = MaxRelativeDifference(ReleaseTimes(c.scene, x0, xs, o), m, xs);
        EXPECT_LT(err, tol <= 1e-13 ? 3 * tol : tol)
            << VectorKernelName(kernel) << " tol " << tol << " release " << c.release << " n " << c.n;
      }
    }
  }
}

TEST(MotionReleaseTimes, KernelsAgreeAndInputIsChecked) {
  const Scene s = Spheroid(0.02, 0.032, 1.0, 30.0);
  const double x0 = 1.05 * *s.x_eq();
  const std::vector<double> xs = Positions(x0, s.x_max(), 37);  // a tail of 1 after 4·9
  ReleaseTimesOptions o;
  o.kernel = VectorKernel::kScalar;
  const std::vector<double> scalar = ReleaseTimes(s, x0, xs, o);
  if (VectorKernelAvailable(VectorKernel::kAvx2)) {
    o.kernel = VectorKernel::kAvx2;
    const std::vector<double> avx2 = ReleaseTimes(s, x0, xs, o);
    for (size_t i = 0; i < xs.size(); ++i) EXPECT_NEAR(avx2[i], scalar[i], 1e-14 * scalar[i]) << i;
  }
  EXPECT_NEAR(scalar.back(), Motion(s, x0).end_time(), 1e-13 * scalar.back());  // x_max itself
  o = ReleaseTimesOptions();
  EXPECT_THROW(ReleaseTimes(s, 0.5 * *s.x_eq(), xs, o), InputError);           // below X
  EXPECT_THROW(ReleaseTimes(s, x0, {xs[2], xs[1]}, o), InputError);             // decreasing
  EXPECT_THROW(ReleaseTimes(s, x0, {1.01 * s.x_max()}, o), InputError);         // beyond x_max
  EXPECT_THROW(ReleaseTimes(Spheroid(0.02, 0.032, 1.0, 30.0, 0.002), x0, xs, o), InputError);  // rods
  o.nodes = 1;
  EXPECT_THROW(ReleaseTimes(s, x0, xs, o), InputError);
  o.nodes = 0;
  o.tolerance = 0.1;
  EXPECT_THROW(ReleaseTimes(s, x0, xs, o), InputError);
  o.tolerance = 1e-13;
  o.g = -1;
  EXPECT_THROW(ReleaseTimes(s, x0, xs, o), InputError);
}

TEST(MotionInput, RejectsOutOfDomain) {
  const Scene s = Spheroid(0.02, 0.032, 10.0, 30.0);
  EXPECT_THROW(Motion(s, 1.01 * s.x_max()), InputError);
  EXPECT_THROW(Motion(s, std::nan("")), InputError);
  MotionOptions o;
  o.g = 0;
  EXPECT_THROW(Motion(s, 0.05, o), InputError);
  o = MotionOptions();
  o.mu = 0.1;
  EXPECT_THROW(Motion(s, 0.05, o), InputError);  // friction needs the ODE
  o.method = MotionMethod::kOde;
  o.mu = -1;
  EXPECT_THROW(Motion(s, 0.05, o), InputError);
  o = MotionOptions();
  o.tolerance = 0.5;
  EXPECT_THROW(Motion(s, 0.05, o), InputError);
  const Motion m(s, 0.05);
  EXPECT_THROW(m.At(-1.0), InputError);
}

}  // namespace
}  // namespace uphill::testing
