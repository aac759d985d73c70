#include "edge_rays_fit.hpp"

#include <ceres/tiny_solver.h>

#include <cmath>

namespace uphill::internal {
namespace {

using Eigen::Vector3d;

constexpr double kLossScalePx = 0.5;  // Cauchy scale b
constexpr double kBiasPriorPx = 0.5;  // the bias parameter's prior width
// A residual that stands for "no fit here": the camera inside the body. The solver rejects a step
// that lands there.
constexpr double kOutsidePx = 1e10;

// The centre seen from the camera centre (scaled space; the centre's y = 0 is unchanged by it).
Vector3d FromEye(const EdgeRays& problem, double x, double z) {
  return {x - problem.eye.x(), -problem.eye.y(), z - problem.eye.z()};
}

}  // namespace

void RobustEdgeResiduals(const EdgeRays& problem, const double* p, double* residuals, double* jacobian) {
  const int n = static_cast<int>(problem.rays.size()), m = n + 1;
  const Vector3d c = FromEye(problem, p[0], p[1]);
  const double c2 = c.squaredNorm(), a = problem.a, k = problem.px_per_rad;
  if (!(c2 > a * a)) {
    for (int i = 0; i < m; ++i) residuals[i] = kOutsidePx;
    if (jacobian)
      for (int i = 0; i < 3 * m; ++i) jacobian[i] = 0;
    return;
  }
  const double psi = std::asin(a / std::sqrt(c2));
  const Vector3d dpsi = (-a / (c2 * std::sqrt(c2 - a * a))) * c;
  constexpr double b2 = kLossScalePx * kLossScalePx;
  for (int i = 0; i < n; ++i) {
    const Vector3d& r = problem.rays[i];
    const double s = r.cross(c).norm(), co = r.dot(c);
    const double e = (std::atan2(s, co) - psi) * k - p[2];
    const double root = std::sqrt(b2 * std::log1p(e * e / b2));
    residuals[i] = e < 0 ? -root : root;
    if (!jacobian) continue;
    // d(sign(e)·sqrt(ρ(e²)))/de = ρ'(e²)·|e| / sqrt(ρ(e²)), which tends to 1 as e → 0.
    const double chain = root > 0 ? std::abs(e) / ((1 + e * e / b2) * root) : 1.0;
    const Vector3d dphi = s > 0 ? Vector3d(((co / c2) * c - r) / s) : Vector3d::Zero();
    const Vector3d de = k * (dphi - dpsi);
    jacobian[i] = chain * de.x();
    jacobian[i + m] = chain * de.z();
    jacobian[i + 2 * m] = -chain;
  }
  residuals[n] = p[2] / kBiasPriorPx;
  if (jacobian) {
    jacobian[n] = 0;
    jacobian[n + m] = 0;
    jacobian[n + 2 * m] = 1 / kBiasPriorPx;
  }
}

namespace {

// ceres::TinySolver's function.
struct SolverFunction {
  using Scalar = double;
  enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = 3 };
  const EdgeRays& problem;
  int NumResiduals() const { return static_cast<int>(problem.rays.size()) + 1; }
  bool operator()(const double* p, double* residuals, double* jacobian) const {
    RobustEdgeResiduals(problem, p, residuals, jacobian);
    return true;
  }
};

}  // namespace

double EdgeRayResidualPx(const EdgeRays& problem, const Vector3d& ray, double x, double z, double bias) {
  const Vector3d c = FromEye(problem, x, z);
  const double phi = std::atan2(ray.cross(c).norm(), ray.dot(c));
  return (phi - std::asin(problem.a / c.norm())) * problem.px_per_rad - bias;
}

EdgeRaysSolution FitEdgeRays(const EdgeRays& problem, double x0, double z0, double bias0) {
  const SolverFunction function{problem};
  ceres::TinySolver<SolverFunction> solver;
  solver.options.max_num_iterations = 30;
  // The centre's metres are near 0.5: a relative step of 1e-9 is about 1e-6 px, far below the edge
  // points' scatter; tighter only adds iterations.
  solver.options.parameter_tolerance = 1e-9;
  solver.options.function_tolerance = 1e-12;  // px², absolute (TinySolver's convention)
  Eigen::Vector3d p(x0, z0, bias0);
  solver.Solve(function, &p);
  EdgeRaysSolution out;
  out.x = p[0];
  out.z = p[1];
  out.bias = p[2];
  out.iterations = solver.summary.iterations;
  out.finite = p.allFinite();
  return out;
}

}  // namespace uphill::internal
