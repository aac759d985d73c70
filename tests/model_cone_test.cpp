// Property tests of the double cone (docs/physics.md "Double cone").
// Tolerances and references: model_property_support.hpp.
#include <gtest/gtest.h>

#include "model_property_support.hpp"

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// 7. The double cone.

struct ConeCase {
  double R = 0, h = 0;
  Rails rails;
  std::string Describe() const {
    return "R=" + Str(R) + " h=" + Str(h) + " theta=" + Str(rails.theta) + " alpha=" + Str(rails.alpha);
  }
};

// R/h in [0.05, 3], θ in [0, 60°], α in [2°, 150°]; some cannot rest (Q ≤ 0).
ConeCase RandomCone(Gen& gen) {
  ConeCase c;
  c.R = gen.LogUniform(5e-3, 5e-2);
  c.h = c.R / gen.LogUniform(0.05, 3.0);
  c.rails = Rails::FromAngles(gen.Uniform(0.0, 60 * kDeg), gen.Uniform(2 * kDeg, 150 * kDeg));
  return c;
}

TEST(DoubleCone, PathIsStraightAndTangentToTheRails) {
  Gen gen(0x5eed000d);
  int refused = 0, checked = 0;
  for (int i = 0; i < 300; ++i) {
    const ConeCase c = RandomCone(gen);
    SCOPED_TRACE(c.Describe());
    const double B = c.rails.tan_theta, T = c.rails.tan_half_alpha, k = c.R / c.h;
    if (1 + B * B - k * T * k * T <= 0) {
      EXPECT_THROW(Scene(Body::DoubleCone(c.R, c.h), c.rails), InputError);
      ++refused;
      continue;
    }
    ++checked;
    const Scene scene(Body::DoubleCone(c.R, c.h), c.rails);
    const auto& cone = *scene.cone();
    ASSERT_LT(scene.x_low(), scene.x_max());
    const DoubleConeOnLineRails<Jet5> cj(Jet5(c.R, 0), Jet5(c.h, 1), Jet5(B, 2), Jet5(T, 3));
    const std::array<double, 4> params{c.R, c.h, B, T};
    const PathPoint first = scene.At(scene.x_low());
    for (double x : PathGrid(scene.x_low(), scene.x_max(), 12)) {
      const PathPoint p = scene.At(x);
      // Slope −B everywhere, and a straight line through the first point (the chord has the
      // rounding of the two heights and of B·Δx: 4u of their magnitudes).
      EXPECT_EQ(p.dzdx, -cone.B());
      EXPECT_NEAR(p.z - first.z, -cone.B() * (x - first.x),
                  4 * kU * (std::abs(p.z) + std::abs(first.z) + std::abs(cone.B() * (x - first.x))));
      // Tangency (paper eq. 12, independent of the closed form): in 113 bits from the model's
      // (x, z), the discriminant Δ1 = (x + z·tanθ − R·k·T)² − Q·(x² + z² − R²) of the contact
      // equation vanishes, up to the change of Δ1 over δz, the bound (*) on z.
      const Quad X = x, Z = p.z, qB = B, qk = Quad(c.R) / c.h, qT = T, qR = c.R;
      const Quad Q = 1 + qB * qB - qk * qk * qT * qT;
      const Quad lin = X + Z * qB - qR * qk * qT;
      const Quad delta1 = lin * lin - Q * (X * X + Z * Z - qR * qR);
      const Sensitive z_sens = FromJet(cj.Z(Jet5(x, 4)), params, scene.x_max());
      // Δ1 is quadratic in z: |Δ1(z + δz) − Δ1(z)| ≤ |∂Δ1/∂z|·δz + |tan²θ − Q|·δz².
      const double d_delta1_dz = ToDouble(abs(2 * qB * lin - 2 * Q * Z));
      const double dz_tol = z_sens.Tol();
      EXPECT_LE(ToDouble(abs(delta1)), 2 * (d_delta1_dz * dz_tol + ToDouble(abs(qB * qB - Q)) * dz_tol * dz_tol))
          << "x=" << x;
      // The double root x_M = lin/Q, and R* the distance from C to the line through both
      // contacts, = the cone's radius k·(h − T·x_M) at the contact.
      const Quad xm = lin / Q;
      const Sensitive xm_sens = FromJet(cj.ContactX(Jet5(x, 4)), params, scene.x_max());
      const Sensitive rs_sens = FromJet(cj.RStar(Jet5(x, 4)), params, scene.x_max());
      EXPECT_NEAR(p.x_contact, ToDouble(xm), xm_sens.Tol() + ToDouble(abs(qB / Q)) * z_sens.Tol());
      const Quad dx = X - xm, dz = Z - qB * xm;
      const double r_ref = ToDouble(sqrt(dx * dx + dz * dz));
      EXPECT_NEAR(p.r_star, r_ref, rs_sens.Tol() + 2 * z_sens.Tol()) << "x=" << x;
      EXPECT_NEAR(p.r_star, ToDouble(qk * (Quad(c.h) - qT * xm)), rs_sens.Tol() + 2 * z_sens.Tol());
      EXPECT_GE(p.r_star, 0.0);
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(checked, 150);
}

TEST(DoubleCone, RollsUpIffBelowTheCriticalInclination) {
  // The verdicts are compared only where θ and θ0 differ by more than 1e-9 relative, far above
  // the few ulp in which θ0 = atan(k·T) and the sign of B are computed.
  Gen gen(0x5eed000e);
  for (int i = 0; i < 1000; ++i) {
    const ConeCase c = RandomCone(gen);
    SCOPED_TRACE(c.Describe());
    const double B = c.rails.tan_theta, T = c.rails.tan_half_alpha, k = c.R / c.h;
    if (1 + B * B - k * T * k * T <= 0) continue;
    const Scene scene(Body::DoubleCone(c.R, c.h), c.rails);
    const double theta = c.rails.theta, theta0 = *scene.theta0();
    if (std::abs(theta - theta0) <= 1e-9 * theta0) continue;
    const bool below = theta < theta0;
    EXPECT_EQ(scene.rolls_up(), below);
    EXPECT_EQ(scene.cone()->B() > 0, below);
    // The centre descends as x grows iff it rolls up.
    EXPECT_EQ(scene.At(scene.x_max()).z < scene.At(scene.x_low()).z, below);
    // θ0 at fixed 3-D opening 2φ (the paper's last formula): another number, the same verdict;
    // none means it rolls up at every inclination.
    const auto theta0_phi = scene.theta0_fixed_phi();
    EXPECT_EQ(!theta0_phi || theta < *theta0_phi, below);
    if (theta0_phi) {
      // Paper: tanθ0 = tanφ·tanψ/sqrt(1 − tan²φ·tan²ψ), tanψ = R/h.
      const double tp = std::tan(c.rails.HalfAngleBetweenRails()) * k;
      EXPECT_NEAR(std::tan(*theta0_phi), tp / std::sqrt(1 - tp * tp),
                  16 * kU * std::tan(*theta0_phi) / (1 - tp * tp));
    }
    // Rest: a cone rests everywhere iff |B| ≤ μ.
    EXPECT_EQ(scene.RestsEverywhere(std::abs(scene.cone()->B()) * 1.001), true);
    EXPECT_EQ(scene.RestsEverywhere(std::abs(scene.cone()->B()) * 0.999), false);
  }
}

TEST(DoubleCone, ContactRadiusVanishesAtTheFallPoint) {
  // At x_fall = h/T the contact reaches the apex: R* = 0. The stable form
  // R* = k·T·(k·T + tanθ·√Q)·(x_fall − x)/(√Q·(k·T·√Q + tanθ)) is exactly 0 there and
  // never negative (elsewhere R* is checked against the 113-bit geometry in
  // PathIsStraightAndTangentToTheRails).
  Gen gen(0x5eed000f);
  for (int i = 0; i < 1000; ++i) {
    const ConeCase c = RandomCone(gen);
    const double B = c.rails.tan_theta, T = c.rails.tan_half_alpha, k = c.R / c.h;
    if (1 + B * B - k * T * k * T <= 0) continue;
    SCOPED_TRACE(c.Describe());
    const Scene scene(Body::DoubleCone(c.R, c.h), c.rails);
    EXPECT_EQ(scene.x_max(), c.h / T);
    const PathPoint p = scene.At(scene.x_max());
    EXPECT_EQ(p.r_star, 0.0);
    // The contact is at the apex, x_M = h/T: (*) with the sensitivities of ContactX.
    const DoubleConeOnLineRails<Jet5> cj(Jet5(c.R, 0), Jet5(c.h, 1), Jet5(B, 2), Jet5(T, 3));
    const Sensitive xm = FromJet(cj.ContactX(Jet5(scene.x_max(), 4)), {c.R, c.h, B, T}, scene.x_max());
    EXPECT_NEAR(p.x_contact, c.h / T, xm.Tol());
    // Just before it, R* is small, positive and proportional to x_fall − x.
    const double x1 = scene.x_max() * (1 - 1e-9), x2 = scene.x_max() * (1 - 2e-9);
    const double r1 = scene.At(x1).r_star, r2 = scene.At(x2).r_star;
    EXPECT_GT(r1, 0.0);
    EXPECT_NEAR(r2 / r1, (scene.x_max() - x2) / (scene.x_max() - x1), 64 * kU);
    EXPECT_TRUE(std::isinf(scene.KineticFactor(scene.x_max())));
  }
}

TEST(DoubleCone, PaperFormsAgreeWithStableFormsAwayFromSEqualsOne) {
  // Paper: A = R·(√Q − k·tanθ·T)/(1 − s), B = (k·T·√Q − tanθ)/(1 − s), s = k²T². Their relative
  // rounding error is u times the cancellation factors of the numerator and of 1 − s:
  //   A: 1 + (√Q + k·tanθ·T)/|√Q − k·tanθ·T| + (1 + s)/|1 − s|,
  //   B: 1 + (k·T·√Q + tanθ)/|k·T·√Q − tanθ| + (1 + s)/|1 − s|,
  // and the stable forms carry (k·T + tanθ)/|k·T − tanθ| for B (B's own conditioning at θ0).
  Gen gen(0x5eed0010);
  int compared = 0;
  for (int i = 0; i < 1000; ++i) {
    const ConeCase c = RandomCone(gen);
    const double B = c.rails.tan_theta, T = c.rails.tan_half_alpha, k = c.R / c.h;
    const double s = k * T * k * T, Q = 1 + B * B - s;
    if (Q <= 0 || std::abs(1 - s) < 1e-3) continue;
    SCOPED_TRACE(c.Describe());
    ++compared;
    const DoubleConeOnLineRails<double> cone(c.R, c.h, B, T);
    const double sq = std::sqrt(Q);
    const double a_paper = c.R * (sq - k * B * T) / (1 - s);
    const double b_paper = (k * T * sq - B) / (1 - s);
    const double den = (1 + s) / std::abs(1 - s);
    const double cond_a = 1 + (sq + k * B * T) / std::abs(sq - k * B * T) + den;
    const double cond_b = 1 + (k * T * sq + B) / std::abs(k * T * sq - B) + den +
                          (k * T + B) / std::abs(k * T - B);
    EXPECT_NEAR(a_paper, cone.A(), 16 * kU * cond_a * std::abs(cone.A()));
    EXPECT_NEAR(b_paper, cone.B(), 16 * kU * cond_b * std::abs(cone.B()));
  }
  EXPECT_GT(compared, 300);
  // At s = 1 exactly (k = 1, T = 1) the paper's forms are 0/0; the stable ones are finite:
  // A = R·(1 + B²)/(B + B) = R·(1 + B²)/(2B), B_dc = (1 − B²)/(B + B) (√Q = B).
  for (double B : {0.25, 0.5, 2.0}) {
    const DoubleConeOnLineRails<double> cone(0.02, 0.02, B, 1.0);
    EXPECT_DOUBLE_EQ(cone.A(), 0.02 * (1 + B * B) / (2 * B));
    EXPECT_DOUBLE_EQ(cone.B(), (1 - B * B) / (2 * B));
    EXPECT_TRUE(std::isnan((0.02 * (std::sqrt(B * B) - B) / (1 - 1.0))));  // the paper's A
  }
}

}  // namespace
}  // namespace uphill::testing
