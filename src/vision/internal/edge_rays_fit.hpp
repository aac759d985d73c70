// The fast path's solve: the body's centre (x, z) and a uniform edge bias fitted to the viewing
// rays of edge points found on its outline (edge_fit.hpp finds them).
//
// In the space where the body is a sphere of radius a (y scaled by s, outline_fit.hpp), a point
// of the outline is seen along a ray tangent to the sphere: the angle φ between the ray and the
// direction of the centre equals the outline's half angle ψ = asin(a / |c|), c the centre seen
// from the camera centre (the centre lies in y = 0, which the scaling keeps). Residual of an edge
// point, in pixels: e = (φ − ψ)·px_per_rad − bias. The bias is the edge locator's uniform offset
// (a blurred or shaded limb), with prior N(0, 0.5 px); the edge points carry a Cauchy loss
// ρ(e²) = b²·log(1 + e²/b²), b = 0.5 px, so that an edge of something else (a shadow, a seam)
// has little say.
//
// Solved by ceres::TinySolver (Levenberg–Marquardt, 3 parameters, dense normal equations) on the
// residuals sign(e)·sqrt(ρ(e²)), whose squares sum to the robust cost itself: the minimiser is
// the one a ceres::Problem with a CauchyLoss per residual reaches (the test checks they agree to
// 1e-7 px), at a fraction of the cost of building a Problem per frame. The Jacobian is analytic:
//   ∂φ/∂c = ((r·c)·c/|c|² − r) / |r × c|,   ∂ψ/∂c = −a·c / (|c|²·sqrt(|c|² − a²)),
// for a unit ray r; only c's x and z depend on the parameters. The test checks it against
// ceres::Jet. Stops when a step is below 1e-9 of the parameters (about 1e-6 px), the cost changes
// by less than 1e-12 px², or after 30 iterations; an edge fit takes 3–5.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace uphill::internal {

struct EdgeRays {
  std::vector<Eigen::Vector3d> rays;  // unit directions of the edge points' viewing rays, scaled space
  Eigen::Vector3d eye;                // camera centre, scaled space
  double a = 0;                       // the body's radius across (the sphere's radius), m
  double px_per_rad = 0;              // pixels per radian of viewing angle near the body
};

struct EdgeRaysSolution {
  double x = 0, z = 0;  // the centre, m
  double bias = 0;      // px
  int iterations = 0;
  bool finite = false;  // the solver returned finite parameters
};

// The solver's residuals at p = (x, z, bias): for each ray, sign(e)·sqrt(ρ(e²)) (px); then the
// bias prior bias / 0.5 px. With `jacobian` non-null, also their derivatives with respect to p,
// column-major ((rays + 1) × 3). A centre at or inside the body's radius from the camera gives
// 1e10 px everywhere (and a zero Jacobian): no step is taken there.
void RobustEdgeResiduals(const EdgeRays& problem, const double* p, double* residuals, double* jacobian);

// Residual e of one edge point (px) for the centre (x, z) and the bias.
double EdgeRayResidualPx(const EdgeRays& problem, const Eigen::Vector3d& ray, double x, double z, double bias);

// The robust fit from the start (x0, z0) and bias0 (px).
EdgeRaysSolution FitEdgeRays(const EdgeRays& problem, double x0, double z0, double bias0 = 0.0);

}  // namespace uphill::internal
