// The model's named hard cases (θ = 0, tiny α, the fall-off, extreme sizes, refused
// input) and no NaN on a dense grid over random and extreme scenes.
// Tolerances and references: model_property_support.hpp.
#include <gtest/gtest.h>

#include "model_property_support.hpp"

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// 8. Hard cases.

TEST(HardCases, ThetaZeroSphereIsTheCancellationFreeCircle) {
  // θ = 0: X = 0 exactly and z = sqrt(R² − x²s²), s = sin(α/2). R − z formed from the model's
  // z is exact (Sterbenz) but inherits z's absolute error, an ulp of R: relative u·R/(R − z),
  // unbounded as x → 0, which no double z can avoid. So the checks are: z itself within 4u·R,
  // i.e. 2–4 ulp (its condition number is ≤ 1 + x²s²/z² ≤ 2 for x ≤ 0.7·x_max, and the model
  // rounds ~6 times: x/x_max, (x_max − x)/x_max, 1 + x/x_max, their product, the sqrt, the
  // factor z_eq = R, the first four halved by the sqrt: ≲ 2 ulp), hence R − z within 4u·R of
  // the cancellation-free x²s²/(R + sqrt(R² − x²s²)); and z' = −x·s²/sqrt(R² − x²s²) to full
  // relative accuracy down to x = 1e-15·x_max.
  Gen gen(0x5eed0011);
  for (int i = 0; i < 300; ++i) {
    const double R = gen.LogUniform(1e-3, 1e-1);
    const Rails rails = Rails::FromAngles(0.0, gen.Uniform(1 * kDeg, 170 * kDeg));
    const Scene scene(Body::Sphere(R), rails);
    SCOPED_TRACE("R=" + Str(R) + " alpha=" + Str(rails.alpha));
    EXPECT_EQ(*scene.x_eq(), 0.0);
    EXPECT_EQ(*scene.z_eq(), R);
    EXPECT_EQ(scene.Rest(0.0)->high, 0.0);
    const Quad T = rails.tan_half_alpha, s2 = T * T / (1 + T * T), qR = R;
    const PathPoint top = scene.At(0.0);
    EXPECT_EQ(top.z, R);
    EXPECT_EQ(top.dzdx, 0.0);
    for (double f : {1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5, 0.7}) {
      const double x = f * scene.x_max();
      const Quad X = x, root = sqrt(qR * qR - X * X * s2);
      const PathPoint p = scene.At(x);
      EXPECT_NEAR(p.z, ToDouble(root), 4 * kU * R) << "f=" << f;
      EXPECT_NEAR(R - p.z, ToDouble(X * X * s2 / (qR + root)), 4 * kU * R) << "f=" << f;
      // z' = −x·s²/z, relative condition ≤ 1 + 2·x²s²/z² ≤ 3: every input at an ulp gives
      // a few ulp (the model's x_max = hypot(R, R/T) and x/x_max roundings included).
      const double dz_ref = ToDouble(-X * s2 / root);
      EXPECT_NEAR(p.dzdx, dz_ref, 16 * kU * std::abs(dz_ref)) << "f=" << f;
    }
  }
}

TEST(HardCases, ThetaZeroSpheroidIsTheEllipseTop) {
  // θ = 0: z = a·sqrt(1 − (x/x_max)²), z' = −a·x/(x_max²·sqrt(1 − (x/x_max)²)); relative
  // accuracy a few ulp (condition ≤ 3 as above).
  Gen gen(0x5eed0012);
  for (int i = 0; i < 300; ++i) {
    SpheroidCase c = gen.Mixed();
    c.rails = Rails::FromAngles(0.0, c.rails.alpha);
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    EXPECT_EQ(*scene.x_eq(), 0.0);
    EXPECT_EQ(scene.x_low(), 0.0);
    const Quad a = c.a, b = c.b, T = c.T(), xm2 = a * a + b * b / (T * T);
    for (double f : {1e-12, 1e-6, 1e-2, 0.3, 0.7}) {
      const double x = f * scene.x_max();
      const Quad X = x, root = sqrt(1 - X * X / xm2);
      const PathPoint p = scene.At(x);
      EXPECT_NEAR(p.z, ToDouble(a * root), 8 * kU * c.a) << "f=" << f;
      const double dz_ref = ToDouble(-a * X / (xm2 * root));
      EXPECT_NEAR(p.dzdx, dz_ref, 16 * kU * std::abs(dz_ref)) << "f=" << f;
    }
  }
}

TEST(HardCases, TinyDivergenceAngle) {
  // α = 1e-8 rad: A ~ 5e-9·a/b, x_max ~ 2e8·b, and the equilibrium sits within
  // x_max·A²·P/(2B²) of the fall-off — below an ulp of x_max unless θ ≲ α. The margin itself
  // (the closed form x_max·cos²ψ0/(1 + sinψ0)) stays accurate; x_eq ≤ x_max; nothing is NaN.
  for (double aspect : {0.5, 1.0, 2.0}) {
    for (double theta : {0.0, 1e-10, 1e-9, 3e-9, 1e-6, 0.1, 0.7}) {
      SpheroidCase c;
      c.a = 0.0125;
      c.b = c.a * aspect;
      c.rails = Rails::FromAngles(theta, 1e-8);
      SCOPED_TRACE(c.Describe());
      const Scene scene = c.MakeScene();
      const double xe = *scene.x_eq(), x_max = scene.x_max();
      EXPECT_LE(xe, x_max);
      const Quad a = c.a, b = c.b, B = c.B(), T = c.T();
      const Quad A = a * T / b, h = sqrt(A * A + B * B), P = 1 + A * A + B * B;
      const Quad x_eq = a * B / (A * h);
      const Quad margin = a * A * P / (h * (sqrt(1 + A * A) * h + B));  // no cancellation
      const auto m = JetModel(c.a, c.b, c.B(), c.T());
      const std::array<double, 4> params{c.a, c.b, c.B(), c.T()};
      EXPECT_NEAR(*scene.FallOffMargin(), ToDouble(margin), FromJet(m.FallOffMargin(), params, 0).Tol());
      EXPECT_NEAR(xe, ToDouble(x_eq), FromJet(m.x_eq(), params, 0).Tol());
      EXPECT_NEAR(*scene.z_eq(), ToDouble(a * h / A), FromJet(m.z_eq(), params, 0).Tol());
      const PathPoint top = scene.At(xe);
      EXPECT_NEAR(top.z, *scene.z_eq(), 8 * kU * *scene.z_eq());
      if (*scene.FallOffMargin() > 1e-6 * x_max) {
        const PointSens s = SpheroidSens(c, xe);
        EXPECT_LE(std::abs(top.dzdx), 16 * kU * std::abs(s.d2zdx2) * x_max);
      }
      for (double x : PathGrid(scene.x_low(), x_max, 32)) {
        const PathPoint p = scene.At(x);
        EXPECT_FALSE(std::isnan(p.z) || std::isnan(p.dzdx) || std::isnan(p.r_star) ||
                     std::isnan(p.x_contact)) << "x=" << x;
        if (x < x_max) ExpectSpheroidPointAccurate(c, p);
      }
    }
  }
}

TEST(HardCases, WithinTwelveDigitsOfTheFallOff) {
  // x = x_max·(1 − δ), δ down to 1e-12 and the last double below x_max. z' must be finite,
  // negative, ~ −z_eq·cosψ0/(x_max·sqrt(2δ)) (leading order; the next term is relatively
  // sqrt(2δ)·tanψ0 ≤ 1e-5 for these cases), and accurate for the x given: the model's
  // own x_max − x is exact (Sterbenz), so the reference is the naive z' in 113 bits with the
  // model's x_max: z' = z_eq·(sinψ0 − tanψ·cosψ0)/x_max, no cancellation this close to x_max,
  // each factor a few roundings, within 32u — no 1/δ amplification.
  Gen gen(0x5eed0013);
  for (int i = 0; i < 300; ++i) {
    const SpheroidCase c = gen.Typical();
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    const double x_max = scene.x_max(), z_eq = *scene.z_eq();
    const Quad a = c.a, b = c.b, B = c.B(), T = c.T(), A = a * T / b, P = 1 + A * A + B * B;
    const Quad qxm = x_max;  // the model's fall-off point
    const Quad cos_psi0 = A * sqrt(P) / sqrt(A * A * P + B * B);
    const double lead = ToDouble(Quad(z_eq) * cos_psi0 / (qxm * sqrt(Quad(2))));
    const double A_d = c.a * c.T() / c.b;
    const double tan_psi0 = c.B() / (A_d * std::sqrt(1 + A_d * A_d + c.B() * c.B()));
    for (double x : {x_max * (1 - 1e-9), x_max * (1 - 1e-11), x_max * (1 - 1e-12),
                     x_max * (1 - 1e-14), std::nextafter(x_max, 0.0)}) {
      const PathPoint p = scene.At(x);
      ASSERT_TRUE(std::isfinite(p.dzdx)) << "x=" << x;
      EXPECT_LT(p.dzdx, 0.0);
      const double delta = (x_max - x) / x_max;  // exact difference, one rounding
      if (tan_psi0 * std::sqrt(2 * delta) < 1e-5) {
        EXPECT_NEAR(p.dzdx * std::sqrt(delta), -lead, 2e-5 * lead) << "x=" << x;
      }
      // z' from the naive formula with x_max² − x² = (x_max − x)(x_max + x) in 113 bits.
      const Quad X = x, sqrt_delta = sqrt(P * A * A * (qxm - X) * (qxm + X));
      const Quad dz = (B - P * A * A * X / sqrt_delta) / (1 + A * A);
      EXPECT_NEAR(p.dzdx, ToDouble(dz), 32 * kU * std::abs(ToDouble(dz))) << "x=" << x;
      EXPECT_TRUE(std::isfinite(p.z) && std::isfinite(p.r_star) && std::isfinite(p.x_contact));
    }
    const PathPoint end = scene.At(x_max);
    EXPECT_EQ(end.dzdx, -kInf);
    EXPECT_TRUE(std::isfinite(end.z) && std::isfinite(end.r_star));
  }
}

TEST(HardCases, RodsWithinTwelveDigitsOfTheFallOff) {
  // The numeric rods path near x_max: z' finite, negative and ~ −C/sqrt(δ), δ = 1 − x/x_max,
  // i.e. z'·sqrt(δ) the same constant for δ from 1e-10 down to the last double below x_max, up
  // to the next term of the expansion, relatively O(sqrt(δ)) ≤ 1e-5·(a modest coefficient), and
  // the fall-off expansion's ~1e-8 in β: asserted within 1e-3.
  Gen gen(0x5eed0018);
  for (int i = 0; i < 100; ++i) {
    const SpheroidCase c = gen.Typical();
    const double r = c.a * gen.LogUniform(1e-3, 0.5);
    SCOPED_TRACE(c.Describe() + " r=" + Str(r));
    const Scene scene(Body::Spheroid(c.a, c.b), c.rails, r);
    const double x_max = scene.x_max();
    double reference = 0;
    for (double x : {x_max * (1 - 1e-10), x_max * (1 - 1e-12), x_max * (1 - 1e-14), std::nextafter(x_max, 0.0)}) {
      const PathPoint p = scene.At(x);
      ASSERT_TRUE(AllFinite(p)) << "x=" << x;
      EXPECT_LT(p.dzdx, 0.0);
      const double scaled = p.dzdx * std::sqrt((x_max - x) / x_max);
      if (reference == 0) reference = scaled;
      EXPECT_NEAR(scaled, reference, 1e-3 * std::abs(reference)) << "x=" << x;
      // z and z' agree: with z' = −C/sqrt(x_max − x), z − z(x_max) = 2·|z'|·(x_max − x), to the
      // same 1e-3, plus the rounding of the two heights (a few u of z_eq each).
      const double rise = 2 * std::abs(p.dzdx) * (x_max - x);
      EXPECT_NEAR(p.z - scene.At(x_max).z, rise, 1e-3 * rise + 16 * kU * *scene.z_eq()) << "x=" << x;
    }
    EXPECT_EQ(scene.At(x_max).dzdx, -kInf);
  }
}

TEST(HardCases, MicrometreAndKilometreBodies) {
  Gen gen(0x5eed0014);
  for (double size : {1e-6, 1e3}) {
    for (int i = 0; i < 60; ++i) {
      SpheroidCase c = gen.Typical();
      const double ratio = c.b / c.a;
      c.a = size * gen.LogUniform(1.0, 3.0);
      c.b = c.a * ratio;
      SCOPED_TRACE(c.Describe());
      const Scene scene = c.MakeScene();
      const double xe = *scene.x_eq();
      EXPECT_LE(std::abs(scene.At(xe).dzdx), 16 * kU * std::abs(SpheroidSens(c, xe).d2zdx2) * scene.x_max());
      for (double x : PathGrid(scene.x_low(), scene.x_max(), 8))
        if (x < scene.x_max()) ExpectSpheroidPointAccurate(c, scene.At(x));
      // On rods (r = a/10) and as a double cone: finite everywhere.
      for (const Scene& s : {c.MakeScene(c.a / 10), Scene(Body::DoubleCone(c.a, 4 * c.a), c.rails)}) {
        for (double x : PathGrid(s.x_low(), s.x_max(), 16)) {
          const PathPoint p = s.At(x);
          EXPECT_FALSE(std::isnan(p.z) || std::isnan(p.dzdx) || std::isnan(p.r_star)) << "x=" << x;
          EXPECT_GE(p.r_star, 0.0);
        }
      }
      // The apparatus at these scales: the same angles.
      const Rails small = Rails::FromApparatus(size * 0.3, size * 0.03, size * 0.045, LConvention::kAlongRail);
      const Rails unit = Rails::FromApparatus(0.3, 0.03, 0.045, LConvention::kAlongRail);
      EXPECT_NEAR(small.tan_theta, unit.tan_theta, 8 * kU * unit.tan_theta);
      EXPECT_NEAR(small.tan_half_alpha, unit.tan_half_alpha, 8 * kU * unit.tan_half_alpha);
    }
  }
}

TEST(HardCases, ConeWithinRelativeTenToMinusTwelveOfTheCriticalAngle) {
  // θ = θ0·(1 ± 1e-12): tanθ differs from k·T by ≥ 1e-12 relative, ~1e4 ulp, so the verdict is
  // decided by the data, not by rounding.
  Gen gen(0x5eed0015);
  for (int i = 0; i < 300; ++i) {
    const double R = gen.LogUniform(5e-3, 5e-2), h = R / gen.LogUniform(0.1, 2.0);
    const double alpha = gen.Uniform(5 * kDeg, 120 * kDeg);
    // θ0 = atan(k·tan(α/2)) does not depend on θ (the cone at θ = 0 may not rest: Q ≤ 0).
    const double theta0 =
        DoubleConeOnLineRails<double>(R, h, 0.0, Rails::FromAngles(0.0, alpha).tan_half_alpha).theta0();
    for (double sign : {-1.0, 1.0}) {
      const double theta = theta0 * (1 + sign * 1e-12);
      if (theta >= std::numbers::pi / 2) continue;
      const Scene scene(Body::DoubleCone(R, h), Rails::FromAngles(theta, alpha));
      SCOPED_TRACE("R=" + Str(R) + " h=" + Str(h) + " sign=" + Str(sign));
      EXPECT_EQ(scene.rolls_up(), sign < 0);
      EXPECT_EQ(scene.cone()->B() > 0, sign < 0);
      EXPECT_EQ(*scene.theta0(), theta0);
      const auto theta0_phi = scene.theta0_fixed_phi();
      EXPECT_EQ(!theta0_phi || theta < *theta0_phi, sign < 0);
    }
  }
}

TEST(HardCases, ConeThatCannotRestOnBothRailsIsRefused) {
  // Q = 1 + tan²θ − (R/h)²·tan²(α/2) ≤ 0. Q = 0 exactly: R = h, tan(α/2) = 1, θ = 0.
  const Rails right_angle{0.0, std::numbers::pi / 2, 0.0, 1.0};
  for (double ratio : {1.0, 1.5, 10.0}) {
    try {
      Scene(Body::DoubleCone(0.02 * ratio, 0.02), right_angle);
      ADD_FAILURE() << "accepted R/h = " << ratio;
    } catch (const InputError& e) {
      EXPECT_EQ(e.quantity(), "body");
      EXPECT_NE(std::string(e.what()).find("cannot rest"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(Scene(Body::DoubleCone(0.02 * 0.999, 0.02), right_angle));
  // Not modelled: a cone on rods.
  EXPECT_THROW(Scene(Body::DoubleCone(0.02, 0.05), Rails::FromAngles(0.01, 0.3), 1e-3), InputError);
}

TEST(HardCases, PositionOutsideThePathIsRefused) {
  Gen gen(0x5eed0016);
  for (int i = 0; i < 50; ++i) {
    const SpheroidCase c = gen.Typical();
    for (const Scene& scene : {c.MakeScene(), c.MakeScene(c.a / 20), Scene(Body::Sphere(c.a), c.rails, c.a / 20),
                               Scene(Body::DoubleCone(c.a, 3 * c.a), c.rails)}) {
      SCOPED_TRACE(c.Describe() + " " + scene.body().Name());
      const double lo = scene.x_low(), hi = scene.x_max();
      for (double x : {std::nextafter(hi, kInf), hi * 2, std::nextafter(lo, -kInf), lo - 1.0, kNaN, kInf, -kInf}) {
        try {
          scene.At(x);
          ADD_FAILURE() << "accepted x = " << x;
        } catch (const InputError& e) {
          EXPECT_EQ(e.quantity(), "x");
          EXPECT_EQ(std::string(e.what()).rfind("x: ", 0), 0u) << e.what();
        }
      }
      EXPECT_NO_THROW(scene.At(lo));
      EXPECT_NO_THROW(scene.At(hi));
    }
  }
}

// Expects InputError naming `quantity` (its quantity() and the start of its message).
void ExpectRefused(const std::function<void()>& f, const std::string& quantity) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected InputError for " << quantity;
  } catch (const InputError& e) {
    EXPECT_EQ(e.quantity(), quantity) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(quantity + ": ", 0), 0u) << e.what();
  }
}

TEST(HardCases, ApparatusRefusesBadMeasurements) {
  const auto h = LConvention::kHorizontal, r = LConvention::kAlongRail;
  for (auto conv : {h, r}) {
    for (double bad : {0.0, -1.0, -0.0, kNaN, kInf, -kInf}) {
      ExpectRefused([&] { Rails::FromApparatus(bad, 0.3, 0.045, conv); }, "L");
      ExpectRefused([&] { Rails::FromApparatus(1.0, 0.3, bad, conv); }, "D");
    }
    for (double bad : {-1e-9, kNaN, kInf, -kInf})
      ExpectRefused([&] { Rails::FromApparatus(1.0, bad, 0.045, conv); }, "H");
  }
  // Along a rail L must exceed hypot(H, D/2): H = 3, D = 8 gives exactly 5.
  ExpectRefused([&] { Rails::FromApparatus(5.0, 3.0, 8.0, r); }, "L");
  ExpectRefused([&] { Rails::FromApparatus(4.0, 3.0, 8.0, r); }, "L");
  const Rails just = Rails::FromApparatus(std::nextafter(5.0, kInf), 3.0, 8.0, r);
  EXPECT_TRUE(std::isfinite(just.tan_theta) && just.tan_theta > 0);
  EXPECT_LT(just.theta, std::numbers::pi / 2);
  // The horizontal convention accepts the same numbers (L is the horizontal distance).
  EXPECT_NO_THROW(Rails::FromApparatus(5.0, 3.0, 8.0, h));
  // H = 0 is allowed (θ = 0).
  EXPECT_EQ(Rails::FromApparatus(1.0, 0.0, 0.045, h).theta, 0.0);
  // Angles, bodies, rods and μ are refused in the same way.
  ExpectRefused([] { Rails::FromAngles(-1e-9, 0.1); }, "theta");
  ExpectRefused([] { Rails::FromAngles(std::numbers::pi / 2, 0.1); }, "theta");
  ExpectRefused([] { Rails::FromAngles(kNaN, 0.1); }, "theta");
  ExpectRefused([] { Rails::FromAngles(0.1, 0.0); }, "alpha");
  ExpectRefused([] { Rails::FromAngles(0.1, std::numbers::pi); }, "alpha");
  ExpectRefused([] { Body::Sphere(0.0); }, "R");
  ExpectRefused([] { Body::Spheroid(0.01, kNaN); }, "b");
  ExpectRefused([] { Body::DoubleCone(0.01, -1.0); }, "h");
  const Rails rails = Rails::FromAngles(0.02, 0.1);
  ExpectRefused([&] { Scene(Body::Sphere(0.01), rails, -1e-3); }, "rod radius");
  ExpectRefused([&] { Scene(Body::Spheroid(0.01, 0.02), rails, kNaN); }, "rod radius");
  ExpectRefused([&] { Scene(Body::Sphere(0.01), rails).Rest(-0.1); }, "mu");
}

// ---------------------------------------------------------------------------------------------
// 9. No NaN anywhere on a dense grid, random cases including the extremes.

TEST(NoNaN, DenseGridOverRandomAndExtremeScenes) {
  Gen gen(0x5eed0017);
  int scenes = 0;
  for (int i = 0; i < 100; ++i) {
    const SpheroidCase c = i % 2 ? gen.Extreme() : gen.Typical();
    std::vector<Scene> all{c.MakeScene(), c.MakeScene(c.a * gen.LogUniform(1e-6, 1.0))};
    const double k = gen.LogUniform(0.05, 3.0);
    const double B = c.B(), T = c.T();
    if (1 + B * B - k * T * k * T > 0) all.emplace_back(Body::DoubleCone(c.a, c.a / k), c.rails);
    for (const Scene& scene : all) {
      SCOPED_TRACE(c.Describe() + " " + scene.body().Name() + " r=" + Str(scene.rod_radius()));
      ++scenes;
      const double lo = scene.x_low(), hi = scene.x_max();
      ASSERT_TRUE(std::isfinite(lo) && std::isfinite(hi) && lo < hi);
      if (scene.x_eq()) {
        ASSERT_TRUE(std::isfinite(*scene.x_eq()) && std::isfinite(*scene.z_eq()));
        const auto band = scene.Rest(0.1);
        ASSERT_TRUE(std::isfinite(band->low) && std::isfinite(band->high));
      }
      for (double x : PathGrid(lo, hi, 128)) {
        const PathPoint p = scene.At(x);
        ASSERT_FALSE(std::isnan(p.z) || std::isnan(p.dzdx) || std::isnan(p.r_star) || std::isnan(p.x_contact))
            << "x=" << x;
        ASSERT_GE(p.r_star, 0.0) << "x=" << x;
        if (x < hi) {
          ASSERT_TRUE(AllFinite(p)) << "x=" << x;
        }
        ASSERT_FALSE(std::isnan(scene.KineticFactor(x))) << "x=" << x;
      }
    }
  }
  EXPECT_GT(scenes, 200);
}

}  // namespace
}  // namespace uphill::testing
