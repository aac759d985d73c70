// The smeared outline's coverage (src/vision/internal/smeared_outline.hpp), the function the
// tracker's full model fits to the pixels, against an independent computation of its definition:
//   c(d) = ∫_{−½}^{½} Φ(−δ(d, τ)/σ) dτ,  δ = (θ(d, C(τ) − O) − asin(a/|C(τ) − O|))·p − b,
// integrated by Boost.Math's adaptive Gauss–Kronrod quadrature, with Φ from Boost.Math's normal
// distribution and the angle θ by the chord formula 2·asin(|d − ŵ|/2) (the code under test uses
// linear pieces in τ, a tabulated Φ and atan2 or its series). The gradient is checked against
// central differences of that quadrature.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>
#include <cstdio>
#include <new>
#include <vector>

#include "internal/smeared_outline.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// A 2-inch ball 0.8 m from the camera (about 48 px in radius at 1500 px per radian).
SmearedBody Body() {
  SmearedBody body;
  body.a = 0.0254;
  body.eye = Vector3d(0.3, -0.8, 0.12);
  body.px_per_rad = 1500;
  body.sigma_px = 0.7;
  return body;
}

double ReferenceCoverage(const SmearedBody& body, const double* p, const Vector3d& d) {
  const boost::math::normal normal;
  const auto integrand = [&](double tau) {
    const Vector3d v(p[kCentreX] + tau * p[kSmearX] - body.eye.x(), -body.eye.y(), p[kCentreZ] + tau * p[kSmearZ] - body.eye.z());
    const double theta = 2 * std::asin(0.5 * (d - v.normalized()).norm());
    const double delta = (theta - std::asin(body.a / v.norm())) * body.px_per_rad - p[kEdgeShift];
    return boost::math::cdf(normal, -delta / body.sigma_px);
  };
  return boost::math::quadrature::gauss_kronrod<double, 61>::integrate(integrand, -0.5, 0.5, 15, 1e-13);
}

// Viewing directions across the smeared outline: 16 rays around the mid-exposure centre, from
// `reach` px inside the outline to `reach` px outside, every `step` px.
std::vector<Vector3d> DirectionsAcross(const SmearedBody& body, const double* p, double reach, double step) {
  const Vector3d w = (Vector3d(p[kCentreX], 0, p[kCentreZ]) - body.eye).normalized();
  const Vector3d e1 = w.cross(Vector3d::UnitY()).normalized(), e2 = w.cross(e1);
  const double beta = std::asin(body.a / (Vector3d(p[kCentreX], 0, p[kCentreZ]) - body.eye).norm());
  std::vector<Vector3d> out;
  for (int k = 0; k < 16; ++k) {
    const double phi = 2 * M_PI * (k + 0.3) / 16;
    for (double s = -reach; s <= reach; s += step) {
      const double theta = beta + s / body.px_per_rad;
      out.push_back(std::cos(theta) * w + std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2));
    }
  }
  return out;
}

// The central difference of coverage(parameters) in parameter q.
template <typename Coverage>
double CentralDifference(const Coverage& coverage, const double* p, int q, double step) {
  double plus[kSmearParameters], minus[kSmearParameters];
  std::copy(p, p + kSmearParameters, plus);
  std::copy(p, p + kSmearParameters, minus);
  plus[q] += step;
  minus[q] -= step;
  return (coverage(plus) - coverage(minus)) / (2 * step);
}

TEST(SmearedOutline, AtRestIsTheSoftEdgeOfTheOutline) {
  const SmearedBody body = Body();
  const double p[kSmearParameters] = {0.32, 0.05, 0.0, 0.0, 0.1};
  const SmearNodes nodes(body, p, Vector2d::Zero(), 1);
  double worst = 0;
  for (const Vector3d& d : DirectionsAcross(body, p, 6, 0.25)) worst = std::max(worst, std::abs(nodes.Coverage(d, nullptr) - ReferenceCoverage(body, p, d)));
  // Tabulated Φ (interpolation error < 2e-11) and the angle's series (< 1e-14 rad).
  EXPECT_LT(worst, 1e-9);
}

TEST(SmearedOutline, SmearedOverTheExposureMatchesTheIntegral) {
  const SmearedBody body = Body();
  // D = (6, 1.5) mm over the exposure: a blur of about 11 px, a quarter of the radius.
  const double p[kSmearParameters] = {0.32, 0.05, 0.006, 0.0015, -0.05};
  const double blur_px = 11.6, radius_px = 48;
  const std::vector<Vector3d> dirs = DirectionsAcross(body, p, 0.5 * blur_px + 4, 0.5);
  // With the pieces the tracker uses, the edge moves by at most 0.02 px (smeared_outline.hpp):
  // at most 0.02 px times the steepest slope of the coverage, φ(0)/σ per px.
  const int pieces = SmearPieces(blur_px, radius_px);
  ASSERT_GT(pieces, 1);
  // With the most pieces (32) the linear pieces' error (blur/32)²/(16·radius) ≈ 2e-4 px.
  for (const auto& [m, tolerance] : {std::pair{pieces, 0.02 * 0.4 / 0.7}, std::pair{32, 3e-4}}) {
    const SmearNodes nodes(body, p, Vector2d::Zero(), m);
    double worst = 0;
    for (const Vector3d& d : dirs) worst = std::max(worst, std::abs(nodes.Coverage(d, nullptr) - ReferenceCoverage(body, p, d)));
    EXPECT_LT(worst, tolerance) << m << " pieces";
  }
}

TEST(SmearedOutline, GradientMatchesDifferencesOfTheIntegral) {
  const SmearedBody body = Body();
  const double p[kSmearParameters] = {0.32, 0.05, 0.006, 0.0015, -0.05};
  const SmearNodes nodes(body, p, Vector2d::Zero(), 32);
  // Steps: 1 µm of the centre or smear is about 2e-3 px; 1e-3 px of edge shift.
  const double steps[kSmearParameters] = {1e-6, 1e-6, 1e-6, 1e-6, 1e-3};
  double worst = 0, largest = 0;
  const std::vector<Vector3d> dirs = DirectionsAcross(body, p, 10, 0.5);
  for (size_t i = 0; i < dirs.size(); i += 4) {
    SmearGradient grad;
    nodes.Coverage(dirs[i], &grad);
    for (int q = 0; q < kSmearParameters; ++q) {
      const double numeric = CentralDifference([&](const double* at) { return ReferenceCoverage(body, at, dirs[i]); }, p, q, steps[q]);
      // In units of coverage per pixel of motion (per px of edge shift for b).
      const double scale = q == kEdgeShift ? 1.0 : 1.0 / 1500 * (Vector3d(p[kCentreX], 0, p[kCentreZ]) - body.eye).norm();
      worst = std::max(worst, std::abs(grad[q] - numeric) * scale);
      largest = std::max(largest, std::abs(numeric) * scale);
    }
  }
  ASSERT_GT(largest, 0.05);  // the rays cross the edge: the gradient is not trivially zero
  // The 32 linear pieces' error (1e-4 of coverage) over the edge's width (~1 px).
  EXPECT_LT(worst, 5e-4);
}

// A body that speeds up during the exposure, against the integral over the exposure's time of the
// physical motion x(t) = x_mid + v·t + ½·a·t², t ∈ [−E/2, E/2] (quadrature in t, not in the model's
// τ): the coverage with the bend A = ½·a·E² matches it, and the straight smear of the same D = v·E
// does not — it is the picture of a centre ahead of the mid-exposure (the tracker's lead on fast
// accelerating balls, issue 10). The truth is the pixel's time average of the moving body.
TEST(SmearedOutline, AcceleratedBodyMatchesTheTimeAverageOfItsMotion) {
  const SmearedBody body = Body();
  const double E = 1.0 / 30;
  const Vector2d mid(0.32, 0.05), v(-1.2, -0.3), a(-2.4, -0.6);  // m, m/s, m/s²: a 3-radius blur
  const boost::math::normal normal;
  const auto physical = [&](const Vector3d& d) {
    const auto integrand = [&](double t) {
      const Vector2d c = mid + v * t + 0.5 * a * t * t;
      const Vector3d w(c.x() - body.eye.x(), -body.eye.y(), c.y() - body.eye.z());
      const double theta = 2 * std::asin(0.5 * (d - w.normalized()).norm());
      const double delta = (theta - std::asin(body.a / w.norm())) * body.px_per_rad;
      return boost::math::cdf(normal, -delta / body.sigma_px);
    };
    return boost::math::quadrature::gauss_kronrod<double, 61>::integrate(integrand, -E / 2, E / 2, 12, 1e-9) / E;
  };
  const double p[kSmearParameters] = {mid.x(), mid.y(), v.x() * E, v.y() * E, 0.0};
  const Vector2d bend = 0.5 * a * E * E;
  // The bend: 2.3 px at this range (1500 px/rad at ~0.81 m); the blur ~74 px over 48 px radius.
  const SmearNodes bent(body, p, Vector2d::Zero(), 32, bend), straight(body, p, Vector2d::Zero(), 32);
  double worst_bent = 0, worst_straight = 0;
  for (const Vector3d& d : DirectionsAcross(body, p, 45, 2.5)) {
    const double truth = physical(d);
    worst_bent = std::max(worst_bent, std::abs(bent.Coverage(d, nullptr) - truth));
    worst_straight = std::max(worst_straight, std::abs(straight.Coverage(d, nullptr) - truth));
  }
  // The 32 linear pieces of a 74 px blur: (74/32)²/(16·48) px ≈ 7e-3 px of edge, and the bend's
  // own curvature between nodes, against coverage slopes of 1/74 per px along the motion.
  EXPECT_LT(worst_bent, 2e-3);
  EXPECT_GT(worst_straight, 4 * worst_bent);
}

// The model's own discretisation, M linear pieces in τ, integrated independently: δ at the nodes
// by the chord formula, Φ from Boost.Math, and the mean of Φ over each piece by Gauss–Kronrod
// (the code under test uses the closed form Ψ, a table, and skips the nodes it can prove lie in
// a saturated tail; the skipping must change nothing).
double PiecewiseCoverage(const SmearedBody& body, const double* p, const Vector3d& d, int m) {
  const boost::math::normal normal;
  std::vector<double> delta(m + 1);
  for (int n = 0; n <= m; ++n) {
    const double tau = -0.5 + static_cast<double>(n) / m;
    const Vector3d v(p[kCentreX] + tau * p[kSmearX] - body.eye.x(), -body.eye.y(), p[kCentreZ] + tau * p[kSmearZ] - body.eye.z());
    const double theta = 2 * std::asin(0.5 * (d - v.normalized()).norm());
    delta[n] = (theta - std::asin(body.a / v.norm())) * body.px_per_rad - p[kEdgeShift];
  }
  double sum = 0;
  const double tail = 9 * body.sigma_px;  // beyond it Φ differs from 0 or 1 by < 1e-19
  for (int n = 0; n < m; ++n) {
    if (std::min(delta[n], delta[n + 1]) > tail) continue;
    if (std::max(delta[n], delta[n + 1]) < -tail) {
      sum += 1;
      continue;
    }
    const auto piece = [&](double t) { return boost::math::cdf(normal, -(delta[n] + t * (delta[n + 1] - delta[n])) / body.sigma_px); };
    sum += boost::math::quadrature::gauss_kronrod<double, 31>::integrate(piece, 0, 1, 10, 1e-13);
  }
  return sum / m;
}

// A ray's first and last rows under a rolling shutter, 4 mm of motion apart (a fast ball over 80
// rows of a phone), the smear 1.6 radii: the nodes of each, and the parameters of the body as the
// row a fraction t of the way between them sees it.
struct RowWindows {
  SmearedBody body = Body();
  double p[kSmearParameters] = {0.32, 0.05, 0.040, 0.010, 0.0};
  Vector2d first{-0.002, -0.0005}, last{0.002, 0.0005};
  int pieces = SmearPieces(78, 48);
  SmearNodes a{body, p, first, pieces}, b{body, p, last, pieces};
  std::array<double, kSmearParameters> At(double t) const {
    const Vector2d offset = first + t * (last - first);
    return {p[kCentreX] + offset.x(), p[kCentreZ] + offset.y(), p[kSmearX], p[kSmearZ], p[kEdgeShift]};
  }
};

// A rolling shutter's rows see the body shifted by a little more each row; their nodes are
// interpolated between the nodes of a ray's first and last rows. Truth: the definition, the
// coverage integral (Gauss–Kronrod over the exposure, erfc) with the body built at the row's own
// offset: the interpolation errs at second order in the rows' span.
TEST(SmearedOutline, RowsBetweenTwoWindowsAreInterpolatedToSecondOrder) {
  const RowWindows w;
  double worst = 0;
  for (double t : {0.25, 0.5, 0.8}) {
    const SmearNodes between(w.a, w.b, t);
    const auto shifted = w.At(t);
    const SmearNodes exact(w.body, shifted.data(), Vector2d::Zero(), w.pieces);
    for (const Vector3d& d : DirectionsAcross(w.body, shifted.data(), 45, 3.0)) {
      // Against the definition, less what the pieces themselves err by (the exact window's).
      const double truth = ReferenceCoverage(w.body, shifted.data(), d);
      worst = std::max(worst, std::abs(between.Coverage(d, nullptr) - truth) - std::abs(exact.Coverage(d, nullptr) - truth));
    }
  }
  std::printf("  worst excess over the exact window's error: %.2e\n", worst);
  // A coverage error of φ(0)/σ per px of edge position: 1e-3 px is 5.7e-4.
  EXPECT_LT(worst, 5.7e-4);
}

// The interpolated nodes live on the stack of each ray's loop: their reach must not depend on
// what that memory held before (node 1's was once summed onto an unset node 0, which valgrind's
// memcheck reported on the phone clip). Built over memory filled with -1e300 and over zeros, the
// coverage is the same, and within the interpolation's bound (the test above) of the exact
// window's, the nodes built at the row's own offset.
TEST(SmearedOutline, InterpolatedNodesDoNotDependOnTheMemoryTheyAreBuiltIn) {
  const RowWindows w;
  const double t = 0.5;
  const auto shifted = w.At(t);
  const SmearNodes exact(w.body, shifted.data(), Vector2d::Zero(), w.pieces);
  auto built_over = [&](double fill, std::vector<double>* memory) {
    memory->assign(sizeof(SmearNodes) / sizeof(double) + 2, fill);
    return new (memory->data()) SmearNodes(w.a, w.b, t);
  };
  std::vector<double> garbage, zeros;
  const SmearNodes* over_garbage = built_over(-1e300, &garbage);
  const SmearNodes* over_zeros = built_over(0.0, &zeros);
  for (const Vector3d& d : DirectionsAcross(w.body, shifted.data(), 45, 1.0)) {
    EXPECT_EQ(over_garbage->Coverage(d, nullptr), over_zeros->Coverage(d, nullptr));
    EXPECT_NEAR(over_garbage->Coverage(d, nullptr), exact.Coverage(d, nullptr), 5.7e-4);
  }
}

TEST(SmearedOutline, LongSmearIsItsLinearPiecesExactly) {
  const SmearedBody body = Body();
  // D = (100, 25) mm: a blur of about 200 px, four radii, on 32 pieces of about 6 px.
  const double p[kSmearParameters] = {0.32, 0.05, 0.100, 0.025, 0.2};
  const int m = 32;
  const SmearNodes nodes(body, p, Vector2d::Zero(), m);
  const double steps[kSmearParameters] = {1e-6, 1e-6, 1e-6, 1e-6, 1e-3};
  double worst = 0, worst_grad = 0, largest_grad = 0;
  int partial = 0;
  const std::vector<Vector3d> dirs = DirectionsAcross(body, p, 115, 2.0);
  for (size_t i = 0; i < dirs.size(); ++i) {
    SmearGradient grad;
    const double c = nodes.Coverage(dirs[i], &grad);
    worst = std::max(worst, std::abs(c - PiecewiseCoverage(body, p, dirs[i], m)));
    partial += c > 1e-3 && c < 1 - 1e-3;
    if (i % 11 != 0) continue;
    for (int q = 0; q < kSmearParameters; ++q) {
      const double numeric =
          CentralDifference([&](const double* at) { return PiecewiseCoverage(body, at, dirs[i], m); }, p, q, steps[q]);
      worst_grad = std::max(worst_grad, std::abs(grad[q] - numeric) * steps[q]);
      largest_grad = std::max(largest_grad, std::abs(numeric) * steps[q]);
    }
  }
  ASSERT_GT(partial, 500);           // most directions lie inside the smear's ramps
  ASSERT_GT(largest_grad, 1e-4);     // and the gradient does not vanish
  // The table's interpolation (< 2e-11) and the angle's series (< 1e-14 rad) alone.
  EXPECT_LT(worst, 1e-9);
  // Central differences of a step 1e-6 m (about 2e-3 px) err by ~1e-10 of coverage.
  EXPECT_LT(worst_grad, 1e-8);
}

}  // namespace
}  // namespace uphill::internal

namespace uphill::internal {
namespace {

// The body's mean relative colour over the part of it that passed over a pixel (the shade the
// smear model multiplies the body's colour by), against its definition integrated by adaptive
// quadrature in τ: ∫ Φ(−δ(τ)/σ)·A(d, C(τ)) dτ / ∫ Φ(−δ(τ)/σ) dτ, A the shading's colour at the
// surface point d meets (or the limb's nearest point) with the body at C(τ). The code under test
// takes the trapezoidal rule on its nodes.
TEST(SmearedOutline, ShadeIsTheCoverageWeightedMeanOfTheShadingOverTheExposure) {
  SmearedBody body = Body();
  // Light from above and from the side: S = 1 + 0.5·n_z + 0.2·n_x (B), 1 (G), 1 − 0.3·n_z (R).
  BodyShading::Coefficients k = BodyShading::Coefficients::Zero();
  k(0, 0) = k(0, 1) = k(0, 2) = 1;
  k(3, 0) = 0.5, k(1, 0) = 0.2, k(3, 2) = -0.3;
  const BodyShading shading(1.0, k);
  body.shading = &shading;
  // D = (40, 10) mm: a smear of about 1.6 radii.
  const double p[kSmearParameters] = {0.32, 0.05, 0.040, 0.010, 0.0};
  const boost::math::normal normal;
  const auto reference = [&](const Vector3d& d) {
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    for (int ch = 0; ch < 3; ++ch) {
      const auto integrand = [&](double tau) {
        const Vector3d v(p[kCentreX] + tau * p[kSmearX] - body.eye.x(), -body.eye.y(), p[kCentreZ] + tau * p[kSmearZ] - body.eye.z());
        const double theta = 2 * std::asin(0.5 * (d - v.normalized()).norm());
        const double delta = (theta - std::asin(body.a / v.norm())) * body.px_per_rad;
        return boost::math::cdf(normal, -delta / body.sigma_px) * shading.At(d, v, body.a)[ch];
      };
      weighted[ch] = boost::math::quadrature::gauss_kronrod<double, 61>::integrate(integrand, -0.5, 0.5, 15, 1e-10);
    }
    return Eigen::Vector3d(weighted / ReferenceCoverage(body, p, d));
  };
  const double blur_px = 78, radius_px = 48;
  const SmearNodes nodes(body, p, Vector2d::Zero(), SmearPieces(blur_px, radius_px));
  double worst = 0, spread = 0;
  for (const Vector3d& d : DirectionsAcross(body, p, 0.5 * blur_px, 2.0)) {
    BodyShading::Basis basis;
    if (nodes.Coverage(d, nullptr, &basis) < 0.02) continue;  // barely reached: its shade weighs nothing
    const cv::Vec3d shade = shading.FromBasis(basis);
    const Eigen::Vector3d want = reference(d);
    for (int ch = 0; ch < 3; ++ch) {
      worst = std::max(worst, std::abs(shade[ch] - want[ch]));
      spread = std::max(spread, std::abs(want[ch] - 1));
    }
  }
  ASSERT_GT(spread, 0.2);  // the shade does vary across the smear
  std::printf("  worst |shade - integral| %.2e\n", worst);
  // Measured 1.5e-3: the trapezoidal rule on the tracker's nodes (a few px apart) across the
  // shading's change over a radius.
  EXPECT_LT(worst, 5e-3);
}

}  // namespace
}  // namespace uphill::internal
