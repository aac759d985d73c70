// Property and numerical-stability tests of the model layer (docs/physics.md), over random valid
// configurations drawn from a fixed-seed std::mt19937_64, plus named hard cases.
//
// Tolerances. u = 2^-53 is the unit roundoff. A binary64 value f that the model computes from
// inputs p (lengths a, b, x; slopes tanθ, tan(α/2)), each carrying a relative error of an ulp
// or so, is expected within
//
//     16·u·( |f| + Σ_p |p·∂f/∂p| + |∂f/∂x|·x_max )                                         (*)
//
// This is the reference file's rule 16·cond·u (tests/reference_cases.hpp) with cond·|f| written
// out as the sum of the input sensitivities, computed by ceres::Jet through the model's own
// templates. The x term uses x_max rather than |x|: x enters the model through x/x_max and
// (x_max − x)/x_max, each rounded to an ulp of a number ≤ 2, i.e. an x error up to ~u·x_max, and
// x_max's own rounding (an ulp of x_max) moves the distance x_max − x by as much; near the
// fall-off this term is the dominant, and genuine, ill-conditioning. A test that uses another
// bound says why next to it.
// High-precision references are the naive formulas of docs/physics.md
// ("Spheroid on line rails") evaluated in 113-bit binary
// floating point (boost::multiprecision::cpp_bin_float_quad), which absorbs their cancellation.
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <algorithm>
#include <array>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "model/input_error.hpp"
#include "model/scene.hpp"

namespace uphill::testing {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;  // unit roundoff, 2^-53
constexpr double kDeg = std::numbers::pi / 180;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Jet1 = ceres::Jet<double, 1>;
using Jet5 = ceres::Jet<double, 5>;
using Quad = boost::multiprecision::cpp_bin_float_quad;

double ToDouble(const Quad& q) { return q.convert_to<double>(); }

// All 17 digits, for traces that must reproduce a case.
std::string Str(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

// ---------------------------------------------------------------------------------------------
// Random configurations

struct SpheroidCase {
  double a = 0, b = 0;  // semi-axes (a = b: sphere)
  Rails rails;
  double B() const { return rails.tan_theta; }
  double T() const { return rails.tan_half_alpha; }
  Scene MakeScene(double rod_radius = 0.0) const {
    return Scene(a == b ? Body::Sphere(a) : Body::Spheroid(a, b), rails, rod_radius);
  }
  std::string Describe() const {
    return "a=" + Str(a) + " b=" + Str(b) + " theta=" + Str(rails.theta) + " alpha=" + Str(rails.alpha);
  }
};

class Gen {
 public:
  explicit Gen(std::uint64_t seed) : rng_(seed) {}
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  double LogUniform(double lo, double hi) { return std::exp(Uniform(std::log(lo), std::log(hi))); }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }
  double Pick(std::initializer_list<double> values) {
    const auto i = std::uniform_int_distribution<std::size_t>(0, values.size() - 1)(rng_);
    return values.begin()[i];
  }

  // Apparatus-like: a in [2 mm, 5 cm], b/a in [1/4, 4], θ in [0, 45°] (5 % exactly 0),
  // α in [2°, 120°]; one in five a sphere.
  SpheroidCase Typical() {
    SpheroidCase c;
    c.a = LogUniform(2e-3, 5e-2);
    c.b = Chance(0.2) ? c.a : c.a * LogUniform(0.25, 4.0);
    const double theta = Chance(0.05) ? 0.0 : Uniform(0.0, 45 * kDeg);
    c.rails = Rails::FromAngles(theta, Uniform(2 * kDeg, 120 * kDeg));
    return c;
  }
  // The extremes: sizes from 1 µm to 1 km, b/a from 1e-3 to 1e3, θ from 0 to 89.9°,
  // α from 1e-8 rad to 179.9°.
  SpheroidCase Extreme() {
    SpheroidCase c;
    c.a = Pick({1e-6, 1e-3, 1.0, 1e3}) * LogUniform(1.0, 10.0);
    c.b = Chance(0.2) ? c.a : c.a * (Chance(0.5) ? Pick({1e-3, 1e3}) : LogUniform(1e-3, 1e3));
    const double theta = Chance(0.5) ? Pick({0.0, 1e-12, 1e-6, 89.9 * kDeg}) : Uniform(0.0, 89.9 * kDeg);
    const double alpha =
        Chance(0.5) ? Pick({1e-8, 1e-4, 179.9 * kDeg}) : Uniform(1e-3, 179.9 * kDeg);
    c.rails = Rails::FromAngles(theta, alpha);
    return c;
  }
  SpheroidCase Mixed() { return Chance(0.8) ? Typical() : Extreme(); }
  // Mixed, but with an equilibrium that binary64 can tell from the fall-off
  // (x_max − x_eq ≥ 1e-6·x_max; at tiny α it is ~A²/B² of x_max, below an ulp).
  SpheroidCase WithResolvedEquilibrium() {
    for (;;) {
      SpheroidCase c = Mixed();
      const Scene s = c.MakeScene();
      if (*s.FallOffMargin() >= 1e-6 * s.x_max()) return c;
    }
  }

 private:
  std::mt19937_64 rng_;
};

// ---------------------------------------------------------------------------------------------
// Sensitivities (the bound (*)) and references

struct Sensitive {
  double value = 0, scale = 0;  // scale = Σ_p |p·∂f/∂p| + |∂f/∂x|·x_max
  double Tol() const { return 16 * kU * (std::abs(value) + scale); }
};

Sensitive FromJet(const Jet5& f, const std::array<double, 4>& p, double x_scale) {
  double s = std::abs(f.v[4]) * x_scale;
  for (int i = 0; i < 4; ++i) s += std::abs(p[i] * f.v[i]);
  return Sensitive{f.a, s};
}

SpheroidOnLineRails<Jet5> JetModel(double a, double b, double B, double T) {
  return SpheroidOnLineRails<Jet5>(Jet5(a, 0), Jet5(b, 1), Jet5(B, 2), Jet5(T, 3));
}

struct PointSens {
  Sensitive z, dzdx, r_star, x_contact;
  double d2zdx2 = 0;
};

// ceres::Jet rounds some values differently from double (it divides by multiplying with the
// reciprocal), so a Jet model's x_max may differ from the double model's in the last ulp. Near
// the fall-off everything depends on the distance x_max − x, so a Jet model is evaluated at the
// same distance from its own x_max as x is from the double model's (exact by Sterbenz).
double JetX(double x, double x_max_double, double x_max_jet) {
  return x > x_max_double / 2 ? x_max_jet - (x_max_double - x) : x;
}

// The spheroid on line rails at x (x_low ≤ x < x_max): values with their sensitivities, and z''.
PointSens SpheroidSens(double a, double b, double B, double T, double x) {
  const auto m = JetModel(a, b, B, T);
  const double x_max = SpheroidOnLineRails<double>(a, b, B, T).x_max();
  const auto p = m.At(Jet5(JetX(x, x_max, m.x_max().a), 4));
  const std::array<double, 4> params{a, b, B, T};
  PointSens s{FromJet(p.z, params, x_max), FromJet(p.dzdx, params, x_max), FromJet(p.r_star, params, x_max),
              FromJet(p.x_contact, params, x_max), 0.0};
  const SpheroidOnLineRails<Jet1> m1{Jet1(a), Jet1(b), Jet1(B), Jet1(T)};
  s.d2zdx2 = m1.At(Jet1(JetX(x, x_max, m1.x_max().a), 0)).dzdx.v[0];
  return s;
}
PointSens SpheroidSens(const SpheroidCase& c, double x) { return SpheroidSens(c.a, c.b, c.B(), c.T(), x); }

// x_rest(μ) with sensitivities to a, b, tanθ, tan(α/2) and μ (the last counted like an input).
Sensitive RestSens(const SpheroidCase& c, double mu) {
  const auto m = JetModel(c.a, c.b, c.B(), c.T());
  const Jet5 x = m.RestX(Jet5(mu, 4));
  return FromJet(x, {c.a, c.b, c.B(), c.T()}, std::abs(mu));
}

// docs/physics.md "Spheroid on line rails": z(x) and the contact, naive forms, in 113-bit arithmetic:
//   z = (B·x + sqrt(Δ))/(1 + A²), Δ = P·(a²(1 + A²) − A²x²), x_M = (x + B·z)/P,
//   R* = distance from C to the line through both contacts = hypot(x − x_M, z − B·x_M).
struct QuadPoint {
  Quad z, dzdx, r_star, x_contact;
};
QuadPoint NaiveSpheroid(double a_, double b_, double B_, double T_, double x_) {
  const Quad a = a_, b = b_, B = B_, T = T_, x = x_;
  const Quad A = a * T / b, A2 = A * A, P = 1 + A2 + B * B;
  const Quad sqrt_delta = sqrt(P * (a * a * (1 + A2) - A2 * x * x));
  QuadPoint q;
  q.z = (B * x + sqrt_delta) / (1 + A2);
  q.dzdx = (B - P * A2 * x / sqrt_delta) / (1 + A2);
  q.x_contact = (x + B * q.z) / P;
  const Quad dx = x - q.x_contact, dz = q.z - B * q.x_contact;
  q.r_star = sqrt(dx * dx + dz * dz);
  return q;
}

// Checks every value of the model's path point at x against the 113-bit naive reference.
void ExpectSpheroidPointAccurate(const SpheroidCase& c, const PathPoint& p) {
  const PointSens s = SpheroidSens(c, p.x);
  const QuadPoint q = NaiveSpheroid(c.a, c.b, c.B(), c.T(), p.x);
  EXPECT_NEAR(p.z, ToDouble(q.z), s.z.Tol()) << "z at x=" << p.x;
  EXPECT_NEAR(p.dzdx, ToDouble(q.dzdx), s.dzdx.Tol()) << "z' at x=" << p.x;
  EXPECT_NEAR(p.r_star, ToDouble(q.r_star), s.r_star.Tol()) << "R* at x=" << p.x;
  EXPECT_NEAR(p.x_contact, ToDouble(q.x_contact), s.x_contact.Tol()) << "x_M at x=" << p.x;
}

// Points of [x_low, x_max]: a uniform grid with both ends, plus points approaching x_max.
std::vector<double> PathGrid(double x_low, double x_max, int n) {
  std::vector<double> xs;
  for (int i = 0; i <= n; ++i) xs.push_back(i == n ? x_max : x_low + (x_max - x_low) * i / n);
  for (double d : {1e-3, 1e-6, 1e-9, 1e-12}) xs.push_back(x_max - d * (x_max - x_low));
  xs.push_back(std::nextafter(x_max, 0.0));
  for (double& x : xs) x = std::clamp(x, x_low, x_max);
  return xs;
}

bool AllFinite(const PathPoint& p) {
  return std::isfinite(p.z) && std::isfinite(p.dzdx) && std::isfinite(p.r_star) &&
         std::isfinite(p.x_contact);
}

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
// 4. Scale invariance: all lengths ×s scale x_eq, x_max, z, R*, x_M by s and leave z' alone.

// Every length-valued output of a scene at the given x (already scaled).
struct Snapshot {
  std::vector<double> lengths, slopes;
};
Snapshot Take(const Scene& scene, const std::vector<double>& xs) {
  Snapshot s;
  if (scene.x_eq()) {
    s.lengths = {*scene.x_eq(), *scene.z_eq(), *scene.FallOffMargin(), scene.Rest(0.05)->high,
                 scene.Rest(0.05)->low};
  }
  s.lengths.push_back(scene.x_max());
  s.lengths.push_back(scene.x_low());
  for (double x : xs) {
    const PathPoint p = scene.At(x);
    s.lengths.insert(s.lengths.end(), {p.z, p.r_star, p.x_contact});
    s.slopes.push_back(p.dzdx);
  }
  return s;
}

// Sample points of a scene's path, away from x_max (scaled copies must stay inside).
std::vector<double> Interior(const Scene& scene) {
  std::vector<double> xs;
  for (double f : {0.0, 0.1, 0.37, 0.5, 0.71, 0.9, 0.999})
    xs.push_back(scene.x_low() + f * (scene.x_max() - scene.x_low()));
  if (scene.x_eq()) xs.push_back(*scene.x_eq());
  return xs;
}

// Scenes with every length multiplied by s: spheroid and sphere on line rails, sphere and
// spheroid on rods, double cone.
std::vector<std::function<Scene(double)>> ScalableScenes(Gen& gen) {
  const SpheroidCase c = gen.Typical();
  const double R = c.a, r = c.a * gen.LogUniform(1e-3, 0.5);
  // The cone's R/h, small enough that it can rest (Q = 1 + B² − k²T² > 0).
  double k = gen.LogUniform(0.05, 1.0);
  while (1 + c.B() * c.B() - k * k * c.T() * c.T() <= 0.01) k /= 2;
  return {
      [=](double s) { return Scene(Body::Spheroid(c.a * s, c.b * s), c.rails); },
      [=](double s) { return Scene(Body::Sphere(R * s), c.rails); },
      [=](double s) { return Scene(Body::Sphere(R * s), c.rails, r * s); },
      [=](double s) { return Scene(Body::Spheroid(c.a * s, c.b * s), c.rails, r * s); },
      [=](double s) { return Scene(Body::DoubleCone(R * s, R / k * s), c.rails); },
  };
}

TEST(ScaleInvariance, PowersOfTwoAreExact) {
  // Multiplying every length by 2^j is exact, and every operation of the model (products,
  // quotients, sqrt, hypot, atan2 of ratios, the rods' Newton iteration and fall-off expansion
  // in an angle) commutes with it exactly, barring under/overflow: the outputs must be the
  // scaled outputs, bit for bit.
  Gen gen(0x5eed0006);
  for (int i = 0; i < 60; ++i) {
    for (const auto& make : ScalableScenes(gen)) {
      const Scene base = make(1.0);
      const std::vector<double> xs = Interior(base);
      const Snapshot ref = Take(base, xs);
      for (int j : {-20, -13, -7, -1, 3, 10}) {  // 2^-20 ≈ 1e-6 … 2^10 ≈ 1e3
        const double s = std::ldexp(1.0, j);
        std::vector<double> scaled_xs;
        for (double x : xs) scaled_xs.push_back(x * s);
        const Snapshot got = Take(make(s), scaled_xs);
        ASSERT_EQ(got.lengths.size(), ref.lengths.size());
        for (std::size_t n = 0; n < ref.lengths.size(); ++n)
          EXPECT_EQ(got.lengths[n], ref.lengths[n] * s) << base.body().Name() << " j=" << j << " n=" << n;
        for (std::size_t n = 0; n < ref.slopes.size(); ++n)
          EXPECT_EQ(got.slopes[n], ref.slopes[n]) << base.body().Name() << " j=" << j << " n=" << n;
      }
    }
  }
  // The apparatus: only the ratios H/L and D/(2L) enter.
  for (int i = 0; i < 200; ++i) {
    const double L = gen.Uniform(0.2, 2.0), H = L * gen.Uniform(0.0, 0.5), D = L * gen.Uniform(5e-3, 0.2);
    for (auto conv : {LConvention::kHorizontal, LConvention::kAlongRail}) {
      const Rails ref = Rails::FromApparatus(L, H, D, conv);
      for (int j : {-20, -3, 10}) {
        const double s = std::ldexp(1.0, j);
        const Rails got = Rails::FromApparatus(L * s, H * s, D * s, conv);
        EXPECT_EQ(got.tan_theta, ref.tan_theta);
        EXPECT_EQ(got.tan_half_alpha, ref.tan_half_alpha);
        EXPECT_EQ(got.theta, ref.theta);
        EXPECT_EQ(got.alpha, ref.alpha);
      }
    }
  }
}

TEST(ScaleInvariance, PowersOfTenWithinTheConditioning) {
  // ×10^k rounds each scaled length (and x) by ≤ u, a relative input perturbation, so each
  // output moves by at most (*) — for the spheroid on line rails with its Jet sensitivities,
  // with the a, b and x terms only (the slopes are untouched), each side's own rounding
  // counted once more. Here the lengths are checked as f(s·inputs)/s against f(inputs).
  Gen gen(0x5eed0007);
  for (int i = 0; i < 100; ++i) {
    const SpheroidCase c = gen.Mixed();
    SCOPED_TRACE(c.Describe());
    const Scene base = c.MakeScene();
    const std::vector<double> xs = Interior(base);
    for (int k = -6; k <= 3; ++k) {
      const double s = std::pow(10.0, k);
      SpheroidCase cs = c;
      cs.a = c.a * s;
      cs.b = c.b * s;
      const Scene scaled = cs.MakeScene();
      const auto m = JetModel(c.a, c.b, c.B(), c.T());
      auto tol = [&](const Jet5& f) {
        return 2 * 16 * kU * (std::abs(f.a) + std::abs(c.a * f.v[0]) + std::abs(c.b * f.v[1]));
      };
      EXPECT_NEAR(*scaled.x_eq() / s, *base.x_eq(), tol(m.x_eq())) << "k=" << k;
      EXPECT_NEAR(*scaled.z_eq() / s, *base.z_eq(), tol(m.z_eq())) << "k=" << k;
      EXPECT_NEAR(scaled.x_max() / s, base.x_max(), tol(m.x_max())) << "k=" << k;
      for (double x : xs) {
        // Within 1e-9·x_max of the fall-off the linearised bound (*) fails (a relative change
        // of u in x can cross x_max); that end is left to the exact powers-of-two test and to
        // HardCases.WithinTwelveDigitsOfTheFallOff.
        const double x_s = x * s;
        if (base.x_max() - x < 1e-9 * base.x_max() || x_s >= scaled.x_max() || x_s < scaled.x_low()) continue;
        const PathPoint p = scaled.At(x_s), q = base.At(x);
        const PointSens sens = SpheroidSens(c, x);
        // The x term: x·s rounds by u·|x| ≤ u·x_max, and both evaluations round x/x_max;
        // (*) with its x_max term covers both.
        auto tol_x = [&](const Sensitive& f) { return 2 * f.Tol(); };
        EXPECT_NEAR(p.z / s, q.z, tol_x(sens.z)) << "k=" << k << " x=" << x;
        EXPECT_NEAR(p.dzdx, q.dzdx, tol_x(sens.dzdx)) << "k=" << k << " x=" << x;
        EXPECT_NEAR(p.r_star / s, q.r_star, tol_x(sens.r_star)) << "k=" << k << " x=" << x;
        EXPECT_NEAR(p.x_contact / s, q.x_contact, tol_x(sens.x_contact)) << "k=" << k << " x=" << x;
      }
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
