// Property tests of a spheroid on round rods (docs/physics.md "Round rods").
// Tolerances and references: model_property_support.hpp.
#include <gtest/gtest.h>

#include "model_property_support.hpp"

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// 6. Round rods.

// The rods' path at x against another evaluation at x: twice the bound (*) computed for the
// sphere of radius a + r on the axis lines (the rods' path is that curve for a = b), once for
// each side; the solver's β (to ~2 ulp relative, an x error ≲ |dx/dβ|·β·2u ≲ 2u·x_max, and the
// rounding of x(β), a few ulp of x_max) stays within the x term of (*).
void ExpectRodsPointNear(const PathPoint& got, const PathPoint& want, const PointSens& s,
                         double r_star_factor) {
  EXPECT_NEAR(got.z, want.z, 2 * s.z.Tol()) << "z at x=" << got.x;
  EXPECT_NEAR(got.dzdx, want.dzdx, 2 * s.dzdx.Tol()) << "z' at x=" << got.x;
  EXPECT_NEAR(got.r_star, want.r_star, 2 * r_star_factor * s.r_star.Tol()) << "R* at x=" << got.x;
  EXPECT_NEAR(got.x_contact, want.x_contact, 2 * s.x_contact.Tol() + 2 * s.r_star.Tol())
      << "x_M at x=" << got.x;
}

TEST(Rods, EqualAxesSpheroidMatchesTheSphereClosedForm) {
  Gen gen(0x5eed0009);
  for (int i = 0; i < 100; ++i) {
    SpheroidCase c = gen.Typical();
    c.b = c.a;
    const double r = c.a * gen.LogUniform(1e-3, 1.0);
    SCOPED_TRACE(c.Describe() + " r=" + Str(r));
    const Scene numeric(Body::Spheroid(c.a, c.a), c.rails, r);  // SpheroidOnRods
    const Scene closed(Body::Sphere(c.a), c.rails, r);          // sphere of radius a + r
    const double R = c.a + r;
    const auto m = JetModel(R, R, c.B(), c.T());
    const std::array<double, 4> params{R, R, c.B(), c.T()};
    EXPECT_NEAR(*numeric.x_eq(), *closed.x_eq(), 2 * FromJet(m.x_eq(), params, 0).Tol());
    EXPECT_NEAR(*numeric.z_eq(), *closed.z_eq(), 2 * FromJet(m.z_eq(), params, 0).Tol());
    EXPECT_NEAR(numeric.x_max(), closed.x_max(), 2 * FromJet(m.x_max(), params, 0).Tol());
    EXPECT_NEAR(numeric.x_low(), closed.x_low(), 2 * FromJet(m.x_low(), params, 0).Tol());
    SpheroidCase enlarged = c;
    enlarged.a = enlarged.b = R;
    for (double mu : {0.0, 0.02, 0.3}) {
      EXPECT_NEAR(numeric.Rest(mu)->high, closed.Rest(mu)->high, 2 * RestSens(enlarged, mu).Tol());
      EXPECT_NEAR(numeric.Rest(mu)->low, closed.Rest(mu)->low, 2 * RestSens(enlarged, -mu).Tol());
    }
    const double x_low = std::max(numeric.x_low(), closed.x_low());
    const double x_max = std::min(numeric.x_max(), closed.x_max());
    for (double x : PathGrid(x_low, x_max, 24)) {
      if (x >= x_max) continue;
      ExpectRodsPointNear(numeric.At(x), closed.At(x), SpheroidSens(enlarged, x), c.a / R);
    }
  }
}

TEST(Rods, TendToLineRailsLinearlyInTheRodRadius) {
  // f(r) − f(0) = f1·r + f2·r² + …: the slopes s(r) = (f(r) − f(0))/r for r = 1e-3, 1e-6, 1e-9
  // (×a) must converge, s(1e-6·a) − s(1e-9·a) ≈ 1e-3·(s(1e-3·a) − s(1e-6·a)), up to the
  // rounding of the two values, 4·(*)/r (at r = 1e-9·a that is ~1e-5 of f/a: the last step
  // tests that the slope is the same to that, not the ratio 1e-3).
  Gen gen(0x5eed000a);
  for (int i = 0; i < 120; ++i) {
    SpheroidCase c = gen.Typical();
    c.rails = Rails::FromAngles(c.rails.theta, gen.Uniform(10 * kDeg, 120 * kDeg));
    SCOPED_TRACE(c.Describe());
    const Scene line = c.MakeScene();
    const std::array<double, 3> radii{1e-3 * c.a, 1e-6 * c.a, 1e-9 * c.a};
    std::vector<Scene> rods;
    for (double r : radii) rods.emplace_back(Body::Spheroid(c.a, c.b), c.rails, r);
    // Each quantity: its value on each scene, and its rounding bound (*) on line rails.
    struct Quantity {
      std::string name;
      std::function<double(const Scene&)> f;
      double tol;
    };
    const auto m = JetModel(c.a, c.b, c.B(), c.T());
    const std::array<double, 4> params{c.a, c.b, c.B(), c.T()};
    std::vector<Quantity> qs{
        {"x_eq", [](const Scene& s) { return *s.x_eq(); }, FromJet(m.x_eq(), params, 0).Tol()},
        {"z_eq", [](const Scene& s) { return *s.z_eq(); }, FromJet(m.z_eq(), params, 0).Tol()},
        {"x_max", [](const Scene& s) { return s.x_max(); }, FromJet(m.x_max(), params, 0).Tol()},
        {"x_rest", [](const Scene& s) { return s.Rest(0.05)->high; }, RestSens(c, 0.05).Tol()},
    };
    for (double f : {0.1, 0.4, 0.7}) {
      const double x = f * line.x_max();
      const PointSens s = SpheroidSens(c, x);
      qs.push_back({"z", [x](const Scene& sc) { return sc.At(x).z; }, s.z.Tol()});
      qs.push_back({"dzdx", [x](const Scene& sc) { return sc.At(x).dzdx; }, s.dzdx.Tol()});
      qs.push_back({"r_star", [x](const Scene& sc) { return sc.At(x).r_star; }, s.r_star.Tol()});
      qs.push_back({"x_contact", [x](const Scene& sc) { return sc.At(x).x_contact; }, s.x_contact.Tol()});
    }
    for (const Quantity& q : qs) {
      SCOPED_TRACE(q.name);
      const double f0 = q.f(line);
      std::array<double, 3> slope, noise;
      for (int k = 0; k < 3; ++k) {
        slope[k] = (q.f(rods[k]) - f0) / radii[k];
        noise[k] = 4 * q.tol / radii[k];
      }
      // The first step: the r² term is at most a few % at r = 1e-3·a.
      EXPECT_NEAR(slope[1], slope[0], 0.05 * std::abs(slope[0]) + noise[0] + noise[1]);
      EXPECT_NEAR(slope[2], slope[1], 2e-3 * std::abs(slope[1] - slope[0]) + noise[1] + noise[2]);
      EXPECT_TRUE(std::isfinite(slope[2]));
    }
  }
}

TEST(Rods, EquilibriumAndRestPositionsHaveTheirSlopes) {
  // x_eq(r) and x_rest(μ, r) are closed forms; At() solves for the contact numerically.
  // z'(x_eq) = 0 and z'(x_rest) = −μ to within z''·δx + the slope's own error, δx being a few
  // ulp of x_max (closed forms and the solver), z'' by a central difference of z' (only a
  // scale for the bound: a factor 2 of slack covers its error).
  Gen gen(0x5eed000b);
  for (int i = 0; i < 100; ++i) {
    const SpheroidCase c = gen.Typical();
    const double r = c.a * gen.LogUniform(1e-4, 1.0);
    SCOPED_TRACE(c.Describe() + " r=" + Str(r));
    const Scene scene = c.MakeScene(r);
    const double x_max = scene.x_max();
    if (x_max - *scene.x_eq() < 1e-6 * x_max) continue;
    auto check = [&](double x, double want) {
      if (x < scene.x_low() || x >= x_max) return;
      const double h = 1e-4 * (x_max - x);
      const double d2 = (scene.At(x + h).dzdx - scene.At(std::max(x - h, scene.x_low())).dzdx) /
                        (x + h - std::max(x - h, scene.x_low()));
      const double tol = 2 * 16 * kU * (std::abs(want) + 2 * std::abs(d2) * x_max);
      EXPECT_NEAR(scene.At(x).dzdx, want, tol) << "x=" << x;
    };
    check(*scene.x_eq(), 0.0);
    for (double mu : {1e-3, 0.05, 0.5}) {
      check(scene.Rest(mu)->high, -mu);
      check(scene.Rest(mu)->low, mu);
    }
    // And X is the maximum of z along the numeric path.
    const double z_top = scene.At(*scene.x_eq()).z;
    EXPECT_NEAR(z_top, *scene.z_eq(), 16 * kU * z_top);
    for (double x : PathGrid(scene.x_low(), x_max, 32)) EXPECT_LE(scene.At(x).z, z_top * (1 + 16 * kU));
  }
}

TEST(Rods, SlopeMatchesFiniteDifferenceOfZ) {
  // The rods' z' comes from the contact normal, z from the root solve: a 6th-order central
  // difference of z (step d/256, d the distance to x_max, as for the line rails) must agree to
  // 1e-11·(z_eq + |z'|·x_max)/d: the truncation as there, and each z rounded by a few u of
  // z_eq plus, through the solve, |z'| times a few ulp of x_max (x(β) is a sum of terms of that
  // size): 1.83·256·(a few u)·(z_eq + |z'|·x_max)/d ≈ 5e-13 of that.
  Gen gen(0x5eed000c);
  for (int i = 0; i < 100; ++i) {
    const SpheroidCase c = gen.Typical();
    const double r = c.a * gen.LogUniform(1e-3, 1.0);
    SCOPED_TRACE(c.Describe() + " r=" + Str(r));
    const Scene scene = c.MakeScene(r);
    const double x_max = scene.x_max(), z_eq = *scene.z_eq();
    for (double f : {0.05, 0.3, 0.6, 0.9}) {
      const double x = scene.x_low() + f * (x_max - scene.x_low());
      const double d = x_max - std::abs(x);
      const double h = d / 256;
      if (x - 3 * h < scene.x_low()) continue;
      const std::array<double, 7> w{-1, 9, -45, 0, 45, -9, 1};
      double fd = 0;
      for (int j = 0; j < 7; ++j) fd += w[j] * scene.At(x + (j - 3) * h).z;
      fd /= 60 * h;
      const double dzdx = scene.At(x).dzdx;
      EXPECT_NEAR(fd, dzdx, 1e-11 * (z_eq + std::abs(dzdx) * x_max) / d) << "x=" << x;
    }
  }
}

}  // namespace
}  // namespace uphill::testing
