// Shared by the model's property tests (model_*_test.cpp): random configurations, the error
// bound (*) below with its sensitivities, and 113-bit references.
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
// ("Spheroid on line rails") evaluated in 113-bit binary floating point
// (boost::multiprecision::cpp_bin_float_quad), which absorbs their cancellation.
#pragma once

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

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;  // unit roundoff, 2^-53
constexpr double kDeg = std::numbers::pi / 180;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Jet1 = ceres::Jet<double, 1>;
using Jet5 = ceres::Jet<double, 5>;
using Quad = boost::multiprecision::cpp_bin_float_quad;

inline double ToDouble(const Quad& q) { return q.convert_to<double>(); }

// All 17 digits, for traces that must reproduce a case.
inline std::string Str(double v) {
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

inline Sensitive FromJet(const Jet5& f, const std::array<double, 4>& p, double x_scale) {
  double s = std::abs(f.v[4]) * x_scale;
  for (int i = 0; i < 4; ++i) s += std::abs(p[i] * f.v[i]);
  return Sensitive{f.a, s};
}

inline SpheroidOnLineRails<Jet5> JetModel(double a, double b, double B, double T) {
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
inline double JetX(double x, double x_max_double, double x_max_jet) {
  return x > x_max_double / 2 ? x_max_jet - (x_max_double - x) : x;
}

// The spheroid on line rails at x (x_low ≤ x < x_max): values with their sensitivities, and z''.
inline PointSens SpheroidSens(double a, double b, double B, double T, double x) {
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
inline PointSens SpheroidSens(const SpheroidCase& c, double x) { return SpheroidSens(c.a, c.b, c.B(), c.T(), x); }

// x_rest(μ) with sensitivities to a, b, tanθ, tan(α/2) and μ (the last counted like an input).
inline Sensitive RestSens(const SpheroidCase& c, double mu) {
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
inline QuadPoint NaiveSpheroid(double a_, double b_, double B_, double T_, double x_) {
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
inline void ExpectSpheroidPointAccurate(const SpheroidCase& c, const PathPoint& p) {
  const PointSens s = SpheroidSens(c, p.x);
  const QuadPoint q = NaiveSpheroid(c.a, c.b, c.B(), c.T(), p.x);
  EXPECT_NEAR(p.z, ToDouble(q.z), s.z.Tol()) << "z at x=" << p.x;
  EXPECT_NEAR(p.dzdx, ToDouble(q.dzdx), s.dzdx.Tol()) << "z' at x=" << p.x;
  EXPECT_NEAR(p.r_star, ToDouble(q.r_star), s.r_star.Tol()) << "R* at x=" << p.x;
  EXPECT_NEAR(p.x_contact, ToDouble(q.x_contact), s.x_contact.Tol()) << "x_M at x=" << p.x;
}

// Points of [x_low, x_max]: a uniform grid with both ends, plus points approaching x_max.
inline std::vector<double> PathGrid(double x_low, double x_max, int n) {
  std::vector<double> xs;
  for (int i = 0; i <= n; ++i) xs.push_back(i == n ? x_max : x_low + (x_max - x_low) * i / n);
  for (double d : {1e-3, 1e-6, 1e-9, 1e-12}) xs.push_back(x_max - d * (x_max - x_low));
  xs.push_back(std::nextafter(x_max, 0.0));
  for (double& x : xs) x = std::clamp(x, x_low, x_max);
  return xs;
}

inline bool AllFinite(const PathPoint& p) {
  return std::isfinite(p.z) && std::isfinite(p.dzdx) && std::isfinite(p.r_star) &&
         std::isfinite(p.x_contact);
}

}  // namespace uphill::testing
