// Property tests of a spheroid (and sphere) on line rails (docs/physics.md "Spheroid on line rails"):
// the equilibrium, the rest band, the slope, the path against 113-bit references, a = b.
// Tolerances and references: model_property_support.hpp.
#include <gtest/gtest.h>

#include "model_property_support.hpp"

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// 1. The unstable equilibrium: z'(x_eq) = 0, z is maximal there, z(x_eq) = z_eq.

TEST(SpheroidEquilibrium, SlopeVanishesAndHeightIsMaximal) {
  Gen gen(0x5eed0001);
  for (int i = 0; i < 400; ++i) {
    const SpheroidCase c = gen.WithResolvedEquilibrium();
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    const double xe = *scene.x_eq(), ze = *scene.z_eq(), x_max = scene.x_max(), x_low = scene.x_low();
    ASSERT_LE(x_low, xe);
    ASSERT_LT(xe, x_max);
    const PathPoint p = scene.At(xe);
    const PointSens s = SpheroidSens(c, xe);
    // z'(x_eq) = 0 to within z''·δx, δx the position error of (*): x_eq itself (a few ulp), and
    // the roundings of x/x_max and of sinψ0 − tanψ·cosψ0 (terms ≤ 1 that cancel at x_eq, each
    // an ulp, i.e. ≲ u·x_max in x since d(tanψ)/dx ≥ 1/x_max).
    EXPECT_LE(std::abs(p.dzdx), 16 * kU * std::abs(s.d2zdx2) * x_max);
    // z(x_eq) = z_eq: z is stationary there, so only the ~5 roundings of
    // z_eq·(cosψ·cosψ0 + sinψ·sinψ0) count.
    EXPECT_NEAR(p.z, ze, 8 * kU * ze);
    // Maximal: on both sides, z(x_eq ± h) ≤ z(x_eq) up to the rounding of the two heights
    // (≤ 8u·z_eq each). Where h is small against the distance to the branch points ±x_max
    // (h ≤ 1e-2 of it), Taylor's theorem gives the drop ½|z''|h² to within a few h/d ≤ 5 %;
    // where that drop exceeds the rounding, it must be seen, strictly.
    const double room = std::min(xe - x_low, x_max - xe);
    for (double side : {-1.0, 1.0}) {
      const double reach = side < 0 ? xe - x_low : x_max - xe;
      for (double f : {0.999, 0.5, 0.1}) {
        if (reach == 0) continue;
        EXPECT_LE(scene.At(xe + side * f * reach).z, p.z + 16 * kU * ze) << "f=" << f;
      }
      for (double f : {1e-2, 1e-3, 1e-4}) {
        if (room == 0) continue;
        const double h = f * room;
        const double drop = p.z - scene.At(xe + side * h).z;
        const double expected = 0.5 * std::abs(s.d2zdx2) * h * h;
        EXPECT_GE(drop, -16 * kU * ze);
        if (expected > 64 * kU * ze) {
          EXPECT_GT(drop, 0.0) << "f=" << f;
        }
        EXPECT_NEAR(drop, expected, 0.05 * expected + 16 * kU * ze) << "side=" << side << " f=" << f;
      }
    }
    // The global maximum over a grid of the whole path.
    for (double x : PathGrid(x_low, x_max, 64)) EXPECT_LE(scene.At(x).z, p.z + 16 * kU * ze);
  }
}

// x_eq, z_eq, x_max, the fall-off margin and x_rest against the naive closed forms in 113 bits.
TEST(SpheroidEquilibrium, ClosedFormsMatchQuadPrecision) {
  Gen gen(0x5eed0002);
  for (int i = 0; i < 400; ++i) {
    const SpheroidCase c = gen.Mixed();
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    const Quad a = c.a, b = c.b, B = c.B(), T = c.T();
    const Quad A = a * T / b, P = 1 + A * A + B * B, h = sqrt(A * A + B * B);
    const Quad x_eq = a * B / (A * h), x_max = sqrt(a * a + (b / T) * (b / T));
    // x_max − x_eq without cancellation (≈ x_max·A²P/(2B²) for small A, below 113 bits of
    // x_max at α = 1e-8): (a/A)·(sqrt(1 + A²) − B/h) = a·A·P/(h·(sqrt(1 + A²)·h + B)).
    const Quad margin = a * A * P / (h * (sqrt(1 + A * A) * h + B));
    const auto m = JetModel(c.a, c.b, c.B(), c.T());
    const std::array<double, 4> params{c.a, c.b, c.B(), c.T()};
    EXPECT_NEAR(*scene.x_eq(), ToDouble(x_eq), FromJet(m.x_eq(), params, 0).Tol());
    EXPECT_NEAR(*scene.z_eq(), ToDouble(a * h / A), FromJet(m.z_eq(), params, 0).Tol());
    EXPECT_NEAR(scene.x_max(), ToDouble(x_max), FromJet(m.x_max(), params, 0).Tol());
    EXPECT_NEAR(*scene.FallOffMargin(), ToDouble(margin), FromJet(m.FallOffMargin(), params, 0).Tol());
    EXPECT_NEAR(scene.x_low(), ToDouble(-x_max * sin(atan2(A * B, sqrt(P)))), FromJet(m.x_low(), params, 0).Tol());
    for (double mu : {1e-3, 0.1}) {
      for (double sign : {1.0, -1.0}) {
        const Quad K = B + sign * mu * (1 + A * A);
        const Quad x_rest = K * a * sqrt(1 + A * A) / (A * sqrt(P * A * A + K * K));
        const auto band = scene.Rest(mu);
        EXPECT_NEAR(sign > 0 ? band->high : band->low, ToDouble(x_rest), RestSens(c, sign * mu).Tol())
            << "mu=" << sign * mu;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 2. The rest band: z'(x_rest(μ)) = −μ, z'(x_rest(−μ)) = +μ, x_rest(0) = x_eq ∈ band.

TEST(SpheroidRest, ClosedFormRestPositionsHaveSlopeMinusMu) {
  Gen gen(0x5eed0003);
  for (int i = 0; i < 400; ++i) {
    const SpheroidCase c = gen.WithResolvedEquilibrium();
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    const double xe = *scene.x_eq(), x_max = scene.x_max(), x_low = scene.x_low();
    // μ = 0: both ends are X, by a different closed form (x_max·B/hypot(A√P, B) against
    // a·B/(A·hypot(A, B))): both well conditioned (cond ≤ 3), so a few ulp.
    const auto band0 = scene.Rest(0.0);
    EXPECT_NEAR(band0->high, xe, 16 * kU * xe);
    EXPECT_NEAR(band0->low, xe, 16 * kU * xe);
    if (c.rails.theta == 0.0) {
      EXPECT_EQ(band0->high, 0.0);
    }
    double last_high = xe, last_low = xe;
    for (double mu : {gen.LogUniform(1e-6, 1e-3), gen.LogUniform(1e-3, 0.3), gen.LogUniform(0.3, 3.0)}) {
      SCOPED_TRACE("mu=" + Str(mu));
      const auto band = scene.Rest(mu);
      ASSERT_TRUE(band.has_value());
      // The band contains X and widens with μ: strictly where it has not reached ±x_max to
      // within 1e-9 (the steps in μ are ≥ 1e-3 relative, far above rounding; at tiny α,
      // x_rest(μ) is within an ulp of x_max for every μ ≫ A·sqrt(P)).
      EXPECT_LE(band->low, last_low);
      EXPECT_GE(band->high, last_high);
      if (band->high < x_max * (1 - 1e-9)) {
        EXPECT_GT(band->high, last_high);
      }
      if (band->low > -x_max * (1 - 1e-9)) {
        EXPECT_LT(band->low, last_low);
      }
      EXPECT_LE(band->high, x_max);
      EXPECT_GE(band->low, -x_max);
      last_low = band->low;
      last_high = band->high;
      // z'(x_rest) = −μ to within: the error of z' evaluated at x_rest, (*), plus z''·δx with
      // δx the error (*) of x_rest itself (the cancellation in K = B − μ(1 + A²) of the
      // nearest rest position shows up there, through ∂x_rest/∂B and ∂x_rest/∂μ).
      for (double sign : {1.0, -1.0}) {
        const double x = sign > 0 ? band->high : band->low;
        if (x < x_low) continue;  // the nearest rest position is off the rails
        // Within 1e-6·x_max of the fall-off z' is too ill-conditioned for this check (z''·δx
        // exceeds μ); HardCases.WithinTwelveDigitsOfTheFallOff covers that end.
        if (x_max - x < 1e-6 * x_max) continue;
        const PointSens s = SpheroidSens(c, x);
        const double tol = s.dzdx.Tol() + std::abs(s.d2zdx2) * RestSens(c, sign * mu).Tol();
        EXPECT_NEAR(scene.At(x).dzdx, -sign * mu, tol) << (sign > 0 ? "farthest" : "nearest");
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 3. z' agrees with the derivative of z: ceres::Jet through the model's z, and a 6th-order
// central difference of z.

TEST(SpheroidSlope, MatchesJetAndFiniteDifferenceOfZ) {
  Gen gen(0x5eed0004);
  for (int i = 0; i < 400; ++i) {
    const SpheroidCase c = gen.Mixed();
    SCOPED_TRACE(c.Describe());
    const SpheroidOnLineRails<double> m(c.a, c.b, c.B(), c.T());
    const SpheroidOnLineRails<Jet1> mj{Jet1(c.a), Jet1(c.b), Jet1(c.B()), Jet1(c.T())};
    const double x_max = m.x_max(), z_eq = m.z_eq();
    const double h0 = std::hypot(m.A() * std::sqrt(m.P()), c.B());
    const double sin_psi0 = c.B() / h0, cos_psi0 = m.A() * std::sqrt(m.P()) / h0;
    for (int k = 0; k < 12; ++k) {
      const double x = m.x_low() + (x_max - m.x_low()) * gen.Uniform(0.0, 0.9999);
      const double dzdx = m.At(x).dzdx;
      // Jet (at the same distance from its own x_max, see JetX): d/dx of z_eq·(cosψ·cosψ0 +
      // (x/x_max)·sinψ0), with cosψ = sqrt(((x_max − x)/x_max)·(1 + x/x_max)), is
      // z_eq/x_max·(sinψ0 + cosψ0·(−(1 + r) + (1 − r))/(2cosψ)), r = x/x_max;
      // the model's z' is z_eq/x_max·(sinψ0 − r·cosψ0/cosψ). Each carries a few u of the
      // magnitudes of its summands: 16u·(|z'| + z_eq/x_max·(sinψ0 + 2·cosψ0/cosψ)).
      const double cos_psi = std::sqrt((x_max - x) / x_max * (1 + x / x_max));
      const double jet_tol =
          16 * kU * (std::abs(dzdx) + z_eq / x_max * (sin_psi0 + 2 * cos_psi0 / cos_psi));
      EXPECT_NEAR(mj.At(Jet1(JetX(x, x_max, mj.x_max().a), 0)).z.v[0], dzdx, jet_tol) << "x=" << x;
      // Finite difference, at points at distance d ≥ 1e-2·x_max from the branch points ±x_max
      // of z (z is analytic inside), step h = d/256 ≈ d·u^(1/7):
      //   truncation ≈ (h⁶/140)·|z⁽⁷⁾| ≲ (1/140)·7!·(h/d)⁶·z_eq/d ≈ 1e-13·z_eq/d,
      //   rounding   ≈ (Σ|w|/60)·u·z_eq/h = 1.83·256·u·z_eq/d ≈ 5e-14·z_eq/d;
      // asserted within 1e-12·z_eq/d.
      const double d = x_max - std::abs(x);
      if (d < 1e-2 * x_max) continue;
      const double h = d / 256;
      const std::array<double, 7> w{-1, 9, -45, 0, 45, -9, 1};
      double fd = 0;
      for (int j = 0; j < 7; ++j) fd += w[j] * m.At(x + (j - 3) * h).z;
      fd /= 60 * h;
      EXPECT_NEAR(fd, dzdx, 1e-12 * z_eq / d) << "x=" << x;
    }
  }
}

// Every value of the path against the naive formulas in 113 bits, with the bound (*): an
// independent check of the stable forms (ψ parametrisation) at random points of random cases,
// up to the last double below x_max.
TEST(SpheroidAccuracy, PathMatchesQuadPrecisionNaiveFormulas) {
  Gen gen(0x5eed0005);
  for (int i = 0; i < 200; ++i) {
    const SpheroidCase c = gen.Mixed();
    SCOPED_TRACE(c.Describe());
    const Scene scene = c.MakeScene();
    for (double x : PathGrid(scene.x_low(), scene.x_max(), 6)) {
      if (x == scene.x_max()) continue;  // z' = −∞ there: no finite bound
      ExpectSpheroidPointAccurate(c, scene.At(x));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 5. A spheroid with a = b is the sphere.

TEST(SpheroidWithEqualAxes, IsTheSphereEverywhere) {
  Gen gen(0x5eed0008);
  for (int i = 0; i < 150; ++i) {
    SpheroidCase c = gen.Mixed();
    c.b = c.a;
    SCOPED_TRACE(c.Describe());
    const Scene sphere(Body::Sphere(c.a), c.rails), spheroid(Body::Spheroid(c.a, c.a), c.rails);
    // The same closed form with the same inputs: identical, bit for bit.
    EXPECT_EQ(*sphere.x_eq(), *spheroid.x_eq());
    EXPECT_EQ(*sphere.z_eq(), *spheroid.z_eq());
    EXPECT_EQ(sphere.x_max(), spheroid.x_max());
    EXPECT_EQ(sphere.x_low(), spheroid.x_low());
    EXPECT_EQ(*sphere.FallOffMargin(), *spheroid.FallOffMargin());
    EXPECT_EQ(sphere.Rest(0.1)->high, spheroid.Rest(0.1)->high);
    EXPECT_EQ(sphere.Rest(0.1)->low, spheroid.Rest(0.1)->low);
    for (double x : PathGrid(sphere.x_low(), sphere.x_max(), 16)) {
      const PathPoint p = sphere.At(x), q = spheroid.At(x);
      EXPECT_EQ(p.z, q.z);
      EXPECT_EQ(p.dzdx, q.dzdx);
      EXPECT_EQ(p.r_star, q.r_star);
      EXPECT_EQ(p.x_contact, q.x_contact);
      EXPECT_EQ(sphere.KineticFactor(x), spheroid.KineticFactor(x));
      if (x == sphere.x_max()) continue;
      // And it is a sphere: the centre is at distance R from each rail line (computed in 113
      // bits from the model's x, z; the distance moves by at most |δz| for an error δz of z,
      // bounded by (*)); the contact is the foot of the perpendicular, and R* the distance from
      // the centre to the line through both feet (each moves by at most tanθ·|δz|, resp. |δz|,
      // beyond its own bound (*)).
      const Quad X = x, Z = p.z, B = c.B(), T = c.T(), d2 = 1 + T * T + B * B;
      const Quad along = (X + B * Z) / d2;  // the rail parameter t of the foot (= x_M)
      const Quad ex = X - along, ey = -along * T, ez = Z - B * along;
      const PointSens s = SpheroidSens(c, x);
      EXPECT_NEAR(ToDouble(sqrt(ex * ex + ey * ey + ez * ez)), c.a, s.z.Tol() + 16 * kU * c.a);
      EXPECT_NEAR(p.x_contact, ToDouble(along), s.x_contact.Tol() + s.z.Tol() * c.B());
      EXPECT_NEAR(p.r_star, ToDouble(sqrt(ex * ex + ez * ez)), s.r_star.Tol() + s.z.Tol());
    }
  }
}

}  // namespace
}  // namespace uphill::testing
