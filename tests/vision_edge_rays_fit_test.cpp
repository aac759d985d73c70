// The fast path's solve (src/vision/internal/edge_rays_fit.hpp). Truths:
// - the rays are made here as the cone of rays tangent to a sphere (a ray at the half angle
//   asin(a/|c|) from the centre's direction), so the centre they came from is known by
//   construction;
// - the Jacobian is checked against ceres::Jet forward-mode derivatives of the residual written
//   with another angle formula (Kahan's 2·atan2(|r − ĉ|, |r + ĉ|), not atan2(|r × c|, r · c));
// - the robust minimiser is checked against ceres::Solve on a ceres::Problem with one
//   AutoDiffCostFunction and one CauchyLoss per edge point, Ceres's own robust treatment.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "internal/edge_rays_fit.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector3d;

constexpr double kA = 0.0254;        // m
constexpr double kPxPerRad = 1950;   // a 1080p camera's focal length
const Vector3d kEye(0.45, -1.1, 0.35);

// `n` rays tangent to the sphere of radius kA at (x, 0, z), seen from kEye, each turned away from
// the tangent by offset_px[i] / kPxPerRad radians (outward positive).
EdgeRays TangentRays(double x, double z, const std::vector<double>& offset_px) {
  EdgeRays problem;
  problem.eye = kEye;
  problem.a = kA;
  problem.px_per_rad = kPxPerRad;
  const Vector3d c = Vector3d(x, 0, z) - kEye;
  const Vector3d axis = c.normalized();
  const Vector3d u = axis.cross(Vector3d::UnitX()).normalized(), w = axis.cross(u);
  const double psi = std::asin(kA / c.norm());
  const int n = static_cast<int>(offset_px.size());
  for (int i = 0; i < n; ++i) {
    const double around = 2 * M_PI * i / n, angle = psi + offset_px[i] / kPxPerRad;
    problem.rays.push_back(std::cos(angle) * axis + std::sin(angle) * (std::cos(around) * u + std::sin(around) * w));
  }
  return problem;
}

// The residual e (px) with Kahan's angle formula, for ceres::Jet.
template <typename T>
T ResidualKahan(const EdgeRays& problem, const Vector3d& r, const T* p) {
  const T c[3] = {p[0] - problem.eye.x(), T(-problem.eye.y()), p[1] - problem.eye.z()};
  const T norm = ceres::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  T minus2 = T(0), plus2 = T(0);
  for (int j = 0; j < 3; ++j) {
    const T unit = c[j] / norm;
    minus2 += (r[j] - unit) * (r[j] - unit);
    plus2 += (r[j] + unit) * (r[j] + unit);
  }
  const T phi = 2.0 * ceres::atan2(ceres::sqrt(minus2), ceres::sqrt(plus2));
  return (phi - ceres::asin(T(problem.a) / norm)) * problem.px_per_rad - p[2];
}

// Ceres cost functions of the reference problem: the residual e, and the bias prior.
struct KahanResidual {
  const EdgeRays* problem;
  Vector3d ray;
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = ResidualKahan(*problem, ray, p);
    return true;
  }
};
struct BiasPrior {
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = p[2] / 0.5;
    return true;
  }
};

TEST(EdgeRaysFit, JacobianAgreesWithJetOfAnotherAngleFormula) {
  std::mt19937_64 random(5);
  std::normal_distribution<double> spread(0, 0.6);
  std::vector<double> offsets(40);
  for (double& o : offsets) o = spread(random);
  offsets[3] = 4.0;  // far out in the Cauchy loss
  offsets[7] = 0.0;  // e = 0 at the true centre: the chain rule's limit
  const EdgeRays problem = TangentRays(0.52, 0.11, offsets);
  const int m = static_cast<int>(problem.rays.size()) + 1;
  for (const Vector3d& at : {Vector3d(0.52, 0.11, 0.0), Vector3d(0.5212, 0.1093, 0.3), Vector3d(0.515, 0.118, -0.4)}) {
    std::vector<double> residuals(m), jacobian(3 * m);
    RobustEdgeResiduals(problem, at.data(), residuals.data(), jacobian.data());
    using Jet = ceres::Jet<double, 3>;
    const Jet p[3] = {Jet(at[0], 0), Jet(at[1], 1), Jet(at[2], 2)};
    for (int i = 0; i + 1 < m; ++i) {
      const Jet e = ResidualKahan(problem, problem.rays[i], p);
      // sign(e)·sqrt(ρ(e²)), ρ(s) = b²·log(1 + s/b²), b = 0.5 px.
      const Jet root = ceres::sqrt(0.25 * ceres::log(1.0 + e * e / 0.25));
      const Jet robust = e.a < 0 ? -root : root;
      if (e.a == 0) {  // Jet's sqrt has no derivative at 0; the limit is de/dp
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(jacobian[i + j * m], e.v[j], 1e-6 * std::abs(e.v[j]) + 1e-9);
        continue;
      }
      EXPECT_NEAR(residuals[i], robust.a, 1e-9) << "ray " << i;
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(jacobian[i + j * m], robust.v[j], 1e-6 * std::abs(robust.v[j]) + 1e-6) << "ray " << i << " d/dp" << j;
    }
    EXPECT_DOUBLE_EQ(residuals[m - 1], at[2] / 0.5);
    EXPECT_DOUBLE_EQ(jacobian[m - 1 + 2 * m], 2.0);
  }
}

TEST(EdgeRaysFit, ExactTangentRaysGiveTheirCentre) {
  const EdgeRays problem = TangentRays(0.61, 0.083, std::vector<double>(64, 0.0));
  const EdgeRaysSolution s = FitEdgeRays(problem, 0.61 + 0.004, 0.083 - 0.003);  // about 8 px away
  ASSERT_TRUE(s.finite);
  // 1e-9 m is 2e-6 px at this distance.
  EXPECT_NEAR(s.x, 0.61, 1e-9);
  EXPECT_NEAR(s.z, 0.083, 1e-9);
  EXPECT_NEAR(s.bias, 0.0, 1e-6);
  EXPECT_LE(s.iterations, 30);
}

TEST(EdgeRaysFit, RobustMinimiserIsCeresProblemWithCauchyLoss) {
  std::mt19937_64 random(17);
  std::normal_distribution<double> noise(0, 0.15);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> offsets(59);
    for (double& o : offsets) o = noise(random) + 0.2;  // a shared edge bias of 0.2 px
    for (int k = 0; k < 6; ++k) offsets[(trial * 7 + k * 11) % 59] += 3.0 + k;  // a shadow's edges
    const double x = 0.4 + 0.01 * trial, z = 0.05 + 0.004 * trial;
    const EdgeRays problem = TangentRays(x, z, offsets);
    const double x0 = x + 0.002, z0 = z - 0.0015;
    const EdgeRaysSolution tiny = FitEdgeRays(problem, x0, z0);
    ASSERT_TRUE(tiny.finite);

    double p[3] = {x0, z0, 0};
    ceres::Problem reference;
    for (const Vector3d& r : problem.rays)
      reference.AddResidualBlock(new ceres::AutoDiffCostFunction<KahanResidual, 1, 3>(new KahanResidual{&problem, r}),
                                 new ceres::CauchyLoss(0.5), p);
    reference.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPrior, 1, 3>(new BiasPrior), nullptr, p);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = 1e-15;
    options.parameter_tolerance = 1e-15;
    options.gradient_tolerance = 1e-15;
    options.max_num_iterations = 200;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &reference, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable());
    // In pixels: metres × px_per_rad / distance (about 1.2 m).
    const double px_per_m = kPxPerRad / (Vector3d(x, 0, z) - kEye).norm();
    EXPECT_NEAR(tiny.x * px_per_m, p[0] * px_per_m, 1e-7) << "trial " << trial;
    EXPECT_NEAR(tiny.z * px_per_m, p[1] * px_per_m, 1e-7) << "trial " << trial;
    EXPECT_NEAR(tiny.bias, p[2], 1e-5) << "trial " << trial;
    // And the outliers had little say: the centre is within 0.1 px of the truth.
    EXPECT_NEAR(tiny.x * px_per_m, x * px_per_m, 0.1);
    EXPECT_NEAR(tiny.z * px_per_m, z * px_per_m, 0.1);
  }
}

TEST(EdgeRaysFit, ResidualOfOneRayIsItsAngularOffset) {
  const EdgeRays problem = TangentRays(0.5, 0.1, {0.0, 0.7, -1.3, 2.5});
  const double expected[4] = {0.0, 0.7, -1.3, 2.5};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(EdgeRayResidualPx(problem, problem.rays[i], 0.5, 0.1, 0.0), expected[i], 1e-9);
    EXPECT_NEAR(EdgeRayResidualPx(problem, problem.rays[i], 0.5, 0.1, 0.25), expected[i] - 0.25, 1e-9);
  }
}

}  // namespace
}  // namespace uphill::internal
