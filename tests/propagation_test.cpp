// Uncertainty propagation (model/propagation.hpp): first-order sensitivities against derivatives
// derived by hand and against central differences of the scalar model; Monte Carlo against first
// order where the model is linear enough, and flagged where it is not; exact order statistics;
// reproducibility; rejected draws; input errors.
#include "model/propagation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>

#include "model/input_error.hpp"
#include "model/scene.hpp"

namespace uphill::testing {
namespace {

// The lab's spheroid (2 × 1.25 × 1.25 inch, long axis across the rails) and Experiment 2.
constexpr double kA = 0.015875, kB = 0.0254;
constexpr double kL = 1.165, kH = 0.300, kD = 0.045;

PropagationOptions Trials(std::uint64_t trials, std::uint64_t seed = 1) {
  PropagationOptions o;
  o.trials = trials;
  o.seed = seed;
  return o;
}

double Sens(const PropagatedValue& y, InputQuantity q) { return y.sensitivity_to(q); }

void ExpectRel(double actual, double expected, double rel, const char* what) {
  EXPECT_NEAR(actual, expected, rel * std::abs(expected)) << what;
}

// ---------------------------------------------------------------------------------------------
// First order

TEST(FirstOrder, SensitivitiesEqualHandDerivatives) {
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0.002}, {kH, 0.001}, {kD, 0.0005}),
                             UncertainBody::Spheroid({kA, 2e-5}, {kB, 3e-5}), {}, Trials(0));
  const double L = kL, H = kH, D = kD, a = kA, b = kB;
  // θ = atan(H/L)
  ExpectRel(Sens(res.theta, InputQuantity::kH), L / (L * L + H * H), 1e-14, "dθ/dH");
  ExpectRel(Sens(res.theta, InputQuantity::kL), -H / (L * L + H * H), 1e-14, "dθ/dL");
  EXPECT_EQ(Sens(res.theta, InputQuantity::kD), 0.0);
  // α = 2·atan(D/(2L))
  ExpectRel(Sens(res.alpha, InputQuantity::kD), 4 * L / (4 * L * L + D * D), 1e-14, "dα/dD");
  ExpectRel(Sens(res.alpha, InputQuantity::kL), -4 * D / (4 * L * L + D * D), 1e-14, "dα/dL");
  EXPECT_EQ(Sens(res.alpha, InputQuantity::kH), 0.0);
  // φ = atan(D/(2ρ)), ρ = sqrt(L² + H²)   (tanφ = tan(α/2)·cosθ)
  const double rho = std::hypot(L, H), den = 4 * rho * rho + D * D;
  ExpectRel(Sens(res.phi, InputQuantity::kD), 2 * rho / den, 1e-14, "dφ/dD");
  ExpectRel(Sens(res.phi, InputQuantity::kL), -2 * D * L / (rho * den), 1e-14, "dφ/dL");
  ExpectRel(Sens(res.phi, InputQuantity::kH), -2 * D * H / (rho * den), 1e-14, "dφ/dH");
  // X = x_eq = 2bHL/(D·S), S = sqrt(c²D² + H²), c = a/(2b)
  const double c = a / (2 * b), S = std::sqrt(c * c * D * D + H * H);
  const double X = 2 * b * H * L / (D * S);
  ExpectRel(res.x_eq->value, X, 1e-14, "X");
  ExpectRel(Sens(*res.x_eq, InputQuantity::kL), X / L, 1e-13, "dX/dL");
  ExpectRel(Sens(*res.x_eq, InputQuantity::kH), 2 * b * L * c * c * D / (S * S * S), 1e-12, "dX/dH");
  ExpectRel(Sens(*res.x_eq, InputQuantity::kD), -X * (1 / D + c * c * D / (S * S)), 1e-13, "dX/dD");
  ExpectRel(Sens(*res.x_eq, InputQuantity::kAcross), -X * c * c * D * D / (a * S * S), 1e-12, "dX/da");
  ExpectRel(Sens(*res.x_eq, InputQuantity::kAlong), X / b * (1 + c * c * D * D / (S * S)), 1e-13,
            "dX/db");
  // x_max = sqrt(a² + (2bL/D)²)
  const double xm = std::hypot(a, 2 * b * L / D);
  ExpectRel(Sens(res.x_max, InputQuantity::kL), (2 * b / D) * (2 * b / D) * L / xm, 1e-13, "dxm/dL");
  ExpectRel(Sens(res.x_max, InputQuantity::kD), -(2 * b * L) * (2 * b * L) / (D * D * D * xm), 1e-13,
            "dxm/dD");
  ExpectRel(Sens(res.x_max, InputQuantity::kAcross), a / xm, 1e-13, "dxm/da");
  ExpectRel(Sens(res.x_max, InputQuantity::kAlong), (2 * L / D) * (2 * L / D) * b / xm, 1e-13,
            "dxm/db");
  // u² = Σ (∂y/∂x_i · u_i)²
  const double uX = std::sqrt(std::pow(X / L * 0.002, 2) +
                              std::pow(2 * b * L * c * c * D / (S * S * S) * 0.001, 2) +
                              std::pow(X * (1 / D + c * c * D / (S * S)) * 0.0005, 2) +
                              std::pow(X * c * c * D * D / (a * S * S) * 2e-5, 2) +
                              std::pow(X / b * (1 + c * c * D * D / (S * S)) * 3e-5, 2));
  ExpectRel(res.x_eq->u_first_order, uX, 1e-12, "u(X)");
  ExpectRel(res.theta.u_first_order,
            std::hypot(L / (L * L + H * H) * 0.001, H / (L * L + H * H) * 0.002), 1e-14, "u(θ)");
}

// The scalar model as a function of the inputs, for central differences.
struct ModelCase {
  const char* name;
  UncertainRails rails;
  UncertainBody body;
  Uncertain rod;
};

Scene SceneOf(const ModelCase& c, const double (&x)[kInputQuantityCount]) {
  auto at = [&](InputQuantity q) { return x[static_cast<int>(q)]; };
  const Rails rails =
      c.rails.given == UncertainRails::Given::kApparatus
          ? Rails::FromApparatus(at(InputQuantity::kL), at(InputQuantity::kH), at(InputQuantity::kD),
                                 c.rails.convention)
          : Rails::FromAngles(at(InputQuantity::kTheta), at(InputQuantity::kAlpha));
  const Body body = c.body.kind == BodyKind::kSphere ? Body::Sphere(at(InputQuantity::kAcross))
                    : c.body.kind == BodyKind::kSpheroid
                        ? Body::Spheroid(at(InputQuantity::kAcross), at(InputQuantity::kAlong))
                        : Body::DoubleCone(at(InputQuantity::kAcross), at(InputQuantity::kAlong));
  return Scene(body, rails, at(InputQuantity::kRodRadius));
}

std::vector<double> Outputs(const Scene& s) {
  std::vector<double> y = {s.rails().theta, s.rails().alpha, s.rails().HalfAngleBetweenRails()};
  if (s.x_eq()) y.push_back(*s.x_eq());
  y.push_back(s.x_max());
  if (s.theta0()) y.push_back(*s.theta0());
  return y;
}

TEST(FirstOrder, MatchesCentralDifferencesOfTheModelAndItsValues) {
  const std::vector<ModelCase> cases = {
      {"sphere, line rails", UncertainRails::Apparatus({1.0, 1}, {0.2, 1}, {0.1, 1}),
       UncertainBody::Sphere({0.0127, 1}), {}},
      {"sphere on rods", UncertainRails::Apparatus({1.165, 1}, {0.3, 1}, {0.2, 1}),
       UncertainBody::Sphere({0.0127, 1}), {0.005, 1}},
      {"spheroid on rods", UncertainRails::Apparatus({1.165, 1}, {0.3, 1}, {0.2, 1}),
       UncertainBody::Spheroid({kA, 1}, {kB, 1}), {0.005, 1}},
      {"spheroid, L along a rail", UncertainRails::Apparatus({0.9, 1}, {0.3, 1}, {0.1, 1}, LConvention::kAlongRail),
       UncertainBody::Spheroid({kA, 1}, {kB, 1}), {}},
      {"spheroid, angles", UncertainRails::Angles({0.1745, 1}, {0.5236, 1}),
       UncertainBody::Spheroid({0.02, 1}, {0.032, 1}), {}},
      {"double cone, angles", UncertainRails::Angles({0.0873, 1}, {1.0472, 1}),
       UncertainBody::DoubleCone({0.05, 1}, {0.1, 1}), {}},
  };
  for (const ModelCase& c : cases) {
    SCOPED_TRACE(c.name);
    PropagationOptions o = Trials(0);
    const PropagationResult res = Propagate(c.rails, c.body, c.rod, o);
    const std::vector<const PropagatedValue*> ys = res.Outputs();
    double x[kInputQuantityCount] = {c.rails.L.value, c.rails.H.value, c.rails.D.value,
                                     c.rails.theta.value, c.rails.alpha.value, c.body.across.value,
                                     c.body.along.value, c.rod.value};
    const std::vector<double> nominal = Outputs(SceneOf(c, x));
    ASSERT_EQ(nominal.size(), ys.size());
    for (std::size_t k = 0; k < ys.size(); ++k)  // the same expressions: the same numbers
      EXPECT_EQ(ys[k]->value, nominal[k]) << ys[k]->name;
    int inputs = 0;
    for (int i = 0; i < kInputQuantityCount; ++i) {
      if (x[i] == 0.0) continue;  // absent from this scene
      if (c.body.kind == BodyKind::kSphere && i == static_cast<int>(InputQuantity::kAlong)) continue;
      ++inputs;
      const double h = 1e-5 * std::abs(x[i]);
      double xp[kInputQuantityCount], xm[kInputQuantityCount];
      std::copy(std::begin(x), std::end(x), xp);
      std::copy(std::begin(x), std::end(x), xm);
      xp[i] += h;
      xm[i] -= h;
      const std::vector<double> yp = Outputs(SceneOf(c, xp)), ym = Outputs(SceneOf(c, xm));
      for (std::size_t k = 0; k < ys.size(); ++k) {
        const double fd = (yp[k] - ym[k]) / (2 * h);
        const double scale = std::max(std::abs(fd), std::abs(ys[k]->value / x[i]) * 1e-6);
        EXPECT_NEAR(ys[k]->sensitivity[i], fd, 1e-6 * scale) << ys[k]->name << " d/d" << i;
      }
    }
    EXPECT_GE(inputs, 4);
  }
}

TEST(FirstOrder, ZeroUncertaintiesGiveExactlyZero) {
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0}),
                             UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(1000));
  for (const PropagatedValue* y : res.Outputs()) {
    SCOPED_TRACE(y->name);
    EXPECT_EQ(y->u_first_order, 0.0);
    EXPECT_EQ(y->u_monte_carlo, 0.0);
    EXPECT_EQ(y->coverage_low, y->mc_mean);
    EXPECT_EQ(y->coverage_high, y->mc_mean);
    EXPECT_NEAR(y->mc_mean, y->value, 1e-15 * std::abs(y->value));  // the batch kernel: few ulp
    EXPECT_FALSE(y->disagrees);
  }
  EXPECT_FALSE(res.disagrees);
  EXPECT_EQ(res.valid_trials, 1000u);
}

TEST(FirstOrder, OutputsThatDependOnNoUncertainInputHaveExactlyZero) {
  // Only D uncertain: θ = atan(H/L) does not move, in either method.
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0.001}),
                             UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(100000));
  EXPECT_EQ(res.theta.u_first_order, 0.0);
  EXPECT_EQ(res.theta.u_monte_carlo, 0.0);
  EXPECT_EQ(res.theta.coverage_low, res.theta.coverage_high);
  EXPECT_FALSE(res.theta.disagrees);
  EXPECT_GT(res.alpha.u_monte_carlo, 0.0);
  // Only H uncertain: the fall-off x_max = hypot(a, b/tan(α/2)) and α do not move.
  const auto h_only = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0.001}, {kD, 0}),
                                UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(100000));
  EXPECT_EQ(h_only.x_max.u_first_order, 0.0);
  EXPECT_EQ(h_only.x_max.u_monte_carlo, 0.0);
  EXPECT_EQ(h_only.alpha.u_monte_carlo, 0.0);
  EXPECT_GT(h_only.x_eq->u_monte_carlo, 0.0);
  EXPECT_GT(h_only.phi.u_monte_carlo, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo

// For small relative uncertainties the model is linear over the spread: MC reproduces first
// order within its own statistical error. For a near-Gaussian output the standard error of the
// sample standard deviation is u/sqrt(2(M − 1)), of the mean u/sqrt(M), and of the 2.5 % order
// statistic sqrt(p(1 − p)/M)/φ(1.96) · u ≈ 2.7·u/sqrt(M).
TEST(MonteCarlo, AgreesWithFirstOrderForSmallUncertainties) {
  const std::uint64_t m = 100000;
  const auto res = Propagate(UncertainRails::Apparatus({kL, 1e-4 * kL}, {kH, 1e-4 * kH}, {kD, 1e-4 * kD}),
                             UncertainBody::Spheroid({kA, 1e-4 * kA}, {kB, 1e-4 * kB}), {},
                             Trials(m));
  EXPECT_EQ(res.valid_trials, m);
  EXPECT_EQ(res.rejected.total(), 0u);
  const double n = static_cast<double>(m);
  for (const PropagatedValue* y : res.Outputs()) {
    SCOPED_TRACE(y->name);
    const double u = y->u_first_order;
    ASSERT_GT(u, 0.0);
    EXPECT_NEAR(y->u_monte_carlo, u, 5 * u / std::sqrt(2 * (n - 1)));
    EXPECT_NEAR(y->mc_mean, y->value, 5 * u / std::sqrt(n));
    EXPECT_NEAR(y->coverage_low, y->value - 1.959964 * u, 5 * 2.7 * u / std::sqrt(n));
    EXPECT_NEAR(y->coverage_high, y->value + 1.959964 * u, 5 * 2.7 * u / std::sqrt(n));
    EXPECT_FALSE(y->disagrees);
  }
  EXPECT_FALSE(res.disagrees);
}

// The lab case of the brief: L = 1165 mm, H = 300 mm, D = 45 mm, u(D) = 1 mm. X lies 0.12 % below
// x_max, but both move together (X ≈ x_max ≈ 2bL/D): X is nearly proportional to 1/D, and at
// u(D)/D = 2.2 % the first-order u differs from Monte Carlo's by ≈ 0.2 %: not flagged. (Closeness
// to x_max is not a nonlinearity of X(D); a large u(D)/D is.)
TEST(MonteCarlo, LabCaseWithOneMillimetreOnDAgrees) {
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0.001}),
                             UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(100000));
  ASSERT_TRUE(res.x_eq.has_value());
  EXPECT_NEAR(res.x_eq->u_monte_carlo / res.x_eq->u_first_order, 1.0, 0.015);
  EXPECT_FALSE(res.x_eq->disagrees);
  EXPECT_FALSE(res.disagrees);
  // Both ends of X's interval stay below x_max's: the body never starts beyond its fall-off.
  EXPECT_LT(res.x_eq->coverage_low, res.x_max.coverage_low);
  EXPECT_LT(res.x_eq->coverage_high, res.x_max.coverage_high);
}

// Strongly nonlinear: u(D) = 7 mm (16 % of D). X ∝ 1/D is convex; its spread is ≈ 10 % wider
// than first order says (asymptotic series: Var(1/(1 + δz)) ≈ δ² + 8δ⁴ + 69δ⁶, δ = u/D), the interval
// is skewed upward, and the flag is raised on X and x_max, not on the angles (α, φ are nearly
// linear in D).
TEST(MonteCarlo, StronglyNonlinearCaseIsFlagged) {
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0.007}),
                             UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(100000));
  const PropagatedValue& X = *res.x_eq;
  EXPECT_TRUE(X.disagrees);
  EXPECT_TRUE(res.x_max.disagrees);
  EXPECT_TRUE(res.disagrees);
  EXPECT_GT(X.u_monte_carlo / X.u_first_order, 1.07);
  EXPECT_LT(X.u_monte_carlo / X.u_first_order, 1.16);
  // Skewed: the upper end lies farther from the value than the lower end.
  EXPECT_GT(X.coverage_high - X.value, 1.3 * (X.value - X.coverage_low));
  EXPECT_GT(X.mc_mean, X.value);
  EXPECT_FALSE(res.alpha.disagrees);
  EXPECT_FALSE(res.phi.disagrees);
  EXPECT_FALSE(res.theta.disagrees);
}

// The coverage interval is the exact pair of order statistics of JCGM 101 §7.7, whether the
// windows or the store-everything path found it; mean and standard deviation equal a two-pass
// computation over the same samples.
// Both kernels: the windows' and the moments' vector pass and their scalar pass.
TEST(MonteCarlo, StatisticsAreThoseOfTheSamples) {
  std::vector<VectorKernel> kernels = {VectorKernel::kScalar};
  if (VectorKernelAvailable(VectorKernel::kAvx2)) kernels.push_back(VectorKernel::kAvx2);
  for (VectorKernel kernel : kernels)
  for (std::uint64_t m : {2001ull, 100000ull}) {
    SCOPED_TRACE(m);
    SCOPED_TRACE(VectorKernelName(kernel));
    PropagationOptions o = Trials(m, 7);
    o.keep_samples = true;
    o.kernel = kernel;
    const auto res = Propagate(UncertainRails::Apparatus({kL, 0.002}, {kH, 0.001}, {kD, 0.003}),
                               UncertainBody::Spheroid({kA, 2e-5}, {kB, 2e-5}), {}, o);
    const auto ys = res.Outputs();
    ASSERT_EQ(res.samples.size(), ys.size());
    const double pm = 0.95 * static_cast<double>(m);
    const std::uint64_t q = static_cast<std::uint64_t>(pm + 0.5);
    const std::uint64_t r = (m - q + 1) / 2;
    for (std::size_t k = 0; k < ys.size(); ++k) {
      SCOPED_TRACE(ys[k]->name);
      std::vector<double> v = res.samples[k];
      ASSERT_EQ(v.size(), m);
      const double mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(m);
      double ss = 0;
      for (double y : v) ss += (y - mean) * (y - mean);
      EXPECT_NEAR(ys[k]->mc_mean, mean, 1e-13 * std::abs(mean));
      EXPECT_NEAR(ys[k]->u_monte_carlo, std::sqrt(ss / static_cast<double>(m - 1)),
                  1e-9 * ys[k]->u_monte_carlo);
      std::sort(v.begin(), v.end());
      EXPECT_EQ(ys[k]->coverage_low, v[r - 1]);
      EXPECT_EQ(ys[k]->coverage_high, v[r + q - 1]);
    }
  }
}

TEST(MonteCarlo, SameSeedSameResultsOtherSeedOtherResults) {
  const auto rails = UncertainRails::Apparatus({kL, 0.002}, {kH, 0.001}, {kD, 0.0005});
  const auto body = UncertainBody::Spheroid({kA, 2e-5}, {kB, 2e-5});
  const auto a = Propagate(rails, body, {}, Trials(70000, 42));
  const auto b = Propagate(rails, body, {}, Trials(70000, 42));
  const auto c = Propagate(rails, body, {}, Trials(70000, 43));
  const auto ya = a.Outputs(), yb = b.Outputs(), yc = c.Outputs();
  for (std::size_t k = 0; k < ya.size(); ++k) {
    SCOPED_TRACE(ya[k]->name);
    // Every number, bit for bit.
    for (auto field : {&PropagatedValue::value, &PropagatedValue::u_first_order, &PropagatedValue::mc_mean,
                       &PropagatedValue::u_monte_carlo, &PropagatedValue::coverage_low,
                       &PropagatedValue::coverage_high})
      EXPECT_EQ(std::memcmp(&(ya[k]->*field), &(yb[k]->*field), sizeof(double)), 0);
    EXPECT_EQ(ya[k]->disagrees, yb[k]->disagrees);
    EXPECT_NE(ya[k]->u_monte_carlo, yc[k]->u_monte_carlo);
    EXPECT_NE(ya[k]->coverage_low, yc[k]->coverage_low);
  }
}

// The vector path (one pass, NarrowAtan's angles) against the scalar path, which is the model's
// own code, trial by trial: the draws are the same bits (gaussian_stream.hpp), so every trial's
// outputs agree to the kernels' rounding: within 8 units of 2^-53, the batch kernels' bound for
// x_eq (batch_convert_test.cpp), NarrowAtan's angles being within 0.6 ulp of atan (measured here:
// ≤ 3.5 units, φ).
TEST(MonteCarlo, VectorTrialsAreTheModelsToTheLastBits) {
  if (!VectorKernelAvailable(VectorKernel::kAvx2)) GTEST_SKIP() << "no AVX2 + FMA here";
  PropagationOptions o = Trials(200000, 11);
  o.keep_samples = true;
  const auto rails = UncertainRails::Apparatus({kL, 0.002}, {kH, 0.001}, {kD, 0.0005});
  o.kernel = VectorKernel::kScalar;
  const auto scalar = Propagate(rails, UncertainBody::Spheroid({kA, 2e-5}, {kB, 2e-5}), {}, o);
  o.kernel = VectorKernel::kAvx2;
  const auto vector = Propagate(rails, UncertainBody::Spheroid({kA, 2e-5}, {kB, 2e-5}), {}, o);
  ASSERT_EQ(scalar.samples.size(), vector.samples.size());
  const auto ys = scalar.Outputs();
  for (std::size_t k = 0; k < ys.size(); ++k) {
    SCOPED_TRACE(ys[k]->name);
    ASSERT_EQ(scalar.samples[k].size(), vector.samples[k].size());
    double worst = 0.0;
    for (std::size_t j = 0; j < scalar.samples[k].size(); ++j) {
      const double s = scalar.samples[k][j], v = vector.samples[k][j];
      worst = std::max(worst, std::abs(v - s) / std::abs(s) / 0x1p-53);
    }
    EXPECT_LE(worst, 8.0);
  }
}

// A draw of one input does not depend on which other inputs are uncertain: with only D uncertain
// and with D and a, the trials' D values are the same.
TEST(MonteCarlo, EachInputHasItsOwnStream) {
  PropagationOptions o = Trials(5000, 3);
  o.keep_samples = true;
  const auto only_d = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0.001}),
                                UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, o);
  const auto d_and_a = Propagate(UncertainRails::Apparatus({kL, 0}, {kH, 0}, {kD, 0.001}),
                                 UncertainBody::Spheroid({kA, 1e-4}, {kB, 0}), {}, o);
  EXPECT_EQ(only_d.samples[1], d_and_a.samples[1]);  // α depends on L and D only
}

TEST(MonteCarlo, UnphysicalDrawsAreCountedAndLeftOut) {
  // H = 1 ± 1 mm: H < 0 in Φ(−1) ≈ 15.87 % of the trials.
  const std::uint64_t m = 100000;
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0}, {0.001, 0.001}, {kD, 0}),
                             UncertainBody::Spheroid({kA, 0}, {kB, 0}), {}, Trials(m));
  const double p = 0.5 * std::erfc(1 / std::sqrt(2.0));
  EXPECT_NEAR(static_cast<double>(res.rejected.negative_height), p * m, 5 * std::sqrt(p * (1 - p) * m));
  EXPECT_EQ(res.rejected.total(), res.rejected.negative_height);
  EXPECT_EQ(res.valid_trials, m - res.rejected.total());
  EXPECT_GE(res.theta.coverage_low, 0.0);  // the statistics see only θ ≥ 0

  // A double cone near the limit of resting on both rails: 1 + tan²θ − (R/h)²tan²(α/2) ≤ 0 for
  // α ≳ 90.1°, i.e. 1.86 standard deviations above α = 84.8° (≈ 3 %).
  const auto cone = Propagate(UncertainRails::Angles({0.05, 0}, {1.48, 0.05}),
                              UncertainBody::DoubleCone({0.05, 0}, {0.05, 0}), {}, Trials(20000));
  EXPECT_GT(cone.rejected.cone_cannot_rest, 300u);
  EXPECT_LT(cone.rejected.cone_cannot_rest, 900u);
  EXPECT_EQ(cone.rejected.total(), cone.rejected.cone_cannot_rest);
  ASSERT_TRUE(cone.theta0.has_value());
  EXPECT_FALSE(cone.x_eq.has_value());

  // L along a rail barely longer than hypot(H, D/2): draws with L ≤ hypot(H, D/2) are impossible.
  const double s = std::hypot(0.3, 0.0225);
  const auto along = Propagate(UncertainRails::Apparatus({s + 0.002, 0.002}, {0.3, 0}, {0.045, 0},
                                                         LConvention::kAlongRail),
                               UncertainBody::Sphere({0.0127, 0}), {}, Trials(20000));
  EXPECT_NEAR(static_cast<double>(along.rejected.impossible_apparatus), 0.1587 * 20000, 300);
}

TEST(MonteCarlo, TrialsZeroIsFirstOrderOnly) {
  const auto res = Propagate(UncertainRails::Apparatus({kL, 0.002}, {kH, 0.001}, {kD, 0.001}),
                             UncertainBody::Sphere({0.0127, 0}), {}, Trials(0));
  EXPECT_GT(res.x_eq->u_first_order, 0.0);
  EXPECT_TRUE(std::isnan(res.x_eq->u_monte_carlo));
  EXPECT_FALSE(res.disagrees);
  EXPECT_EQ(res.trials, 0u);
}

TEST(MonteCarlo, OutputsAreNamedInOrder) {
  const auto s = Propagate(UncertainRails::Angles({0.1, 0.001}, {0.5, 0.001}),
                           UncertainBody::Sphere({0.02, 0}), {}, Trials(200));
  std::vector<std::string> names;
  for (const auto* y : s.Outputs()) names.push_back(y->name);
  EXPECT_EQ(names, (std::vector<std::string>{"theta", "alpha", "phi", "x_eq", "x_max"}));
  const auto c = Propagate(UncertainRails::Angles({0.1, 0.001}, {0.5, 0.001}),
                           UncertainBody::DoubleCone({0.05, 0}, {0.1, 0}), {}, Trials(200));
  names.clear();
  for (const auto* y : c.Outputs()) names.push_back(y->name);
  EXPECT_EQ(names, (std::vector<std::string>{"theta", "alpha", "phi", "x_max", "theta0"}));
  EXPECT_STREQ(c.x_max.unit, "m");
  EXPECT_STREQ(c.theta0->unit, "rad");
}

// ---------------------------------------------------------------------------------------------
// Errors

std::string QuantityOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.quantity();
  }
  return "(no InputError)";
}

TEST(Errors, BadInputThrowsInputErrorNamingTheQuantity) {
  const auto body = UncertainBody::Spheroid({kA, 0}, {kB, 0});
  auto rails = [](Uncertain L, Uncertain H, Uncertain D) {
    return UncertainRails::Apparatus(L, H, D);
  };
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, 0}, {kD, -1e-3}), body, {}, Trials(0)); }), "u(D)");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, NAN}, {kH, 0}, {kD, 0}), body, {}, Trials(0)); }), "u(L)");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, INFINITY}, {kD, 0}), body, {}, Trials(0)); }), "u(H)");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({NAN, 0}, {kH, 0}, {kD, 0}), body, {}, Trials(0)); }), "L");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, 0}, {-0.045, 0}), body, {}, Trials(0)); }), "D");
  EXPECT_EQ(QuantityOf([&] {
              Propagate(rails({kL, 0}, {kH, 0}, {kD, 0}), UncertainBody::Spheroid({kA, -1}, {kB, 0}), {}, Trials(0));
            }),
            "u(a)");
  EXPECT_EQ(QuantityOf([&] {
              Propagate(rails({kL, 0}, {kH, 0}, {kD, 0}), UncertainBody::DoubleCone({0.05, 0}, {0.1, NAN}), {}, Trials(0));
            }),
            "u(h)");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, 0}, {kD, 0}), body, {0.0, 1e-4}, Trials(0)); }), "u(r)");
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, 0}, {kD, 0}), body, {}, Trials(50)); }), "trials");
  PropagationOptions o = Trials(1000);
  o.coverage = 1.0;
  EXPECT_EQ(QuantityOf([&] { Propagate(rails({kL, 0}, {kH, 0}, {kD, 0}), body, {}, o); }), "coverage");
  EXPECT_EQ(QuantityOf([&] {
              Propagate(UncertainRails::Angles({0.1, 0}, {0.5, 0}), UncertainBody::DoubleCone({0.05, 0}, {0.1, 0}),
                        {0.005, 0}, Trials(0));
            }),
            "rod diameter");  // the model's refusal: a double cone on rods is not modelled
  // Fewer than 2 physical trials: α = 179.99° ± 10^6 rad puts almost every draw outside (0, π).
  EXPECT_EQ(QuantityOf([&] {
              Propagate(UncertainRails::Angles({0.1, 0}, {3.1414, 1e6}), body, {}, Trials(100));
            }),
            "Monte Carlo");
}

}  // namespace
}  // namespace uphill::testing
