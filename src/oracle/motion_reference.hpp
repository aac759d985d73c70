// Reference trajectories of a solid spheroid (or sphere, a = b) on line rails, in 50 digits, for
// any initial velocity v0 and rolling resistance μ ≥ 0: the first time its centre reaches each
// of the positions x_i, and the events (turning points, coming to rest, falling off, reaching O).
//
// From the energy balance on each leg (a stretch of constant direction d = ±1, docs/physics.md
// "Energy" and "Rolling resistance"): with the ellipse parameter u = ψ − ψ0 (x = x_max·sinψ,
// z = z_eq·cos u) and the start u_s of the leg,
//     ½·m(u)·u̇² = E(u) = E_s − g·(z(u) − z(u_s)) − g·μ·d·(x(u) − x(u_s)),   m = K·M,
// M = x_max²cos²ψ + z_eq²sin²u, K = 1 + (2/5)/(cos²(ψ+γ) + (A²/P)·sin²(ψ+γ)), so
// t(u) = ∫ sqrt(m/(2E)) du, a quadrature. The leg ends at the first zero of E (a turning point,
// found by a scan and TOMS 748 in 50 digits; at rest for good there when |dz/dx| ≤ μ) or at the
// end of the rails. The map u = c + r·sin(πσ/2) from σ ∈ [−1, 1] onto the leg removes the
// 1/sqrt singularity of a turning point at either end (E ∝ distance, du/dσ ∝ sqrt(distance)), and
// each interval between positions is integrated by Gauss–Kronrod 61 in
// boost::multiprecision::cpp_bin_float_50 to 1e-35. Independent of src/motion (which integrates
// the equation of motion in time, in binary64); its error is far below 1e-20 relative.
// Used by tests/motion_trajectory_test.cpp and `uphill bench motion`.
#pragma once

#include <span>
#include <vector>

namespace uphill::oracle {

enum class TrajectoryEventKind { kTurningPoint, kRest, kFallOff, kReachesO };

struct TrajectoryEvent {
  TrajectoryEventKind kind;
  double t, x;
};

struct TrajectoryReference {
  std::vector<double> times;  // first time at xs[i]; +∞ if never reached
  std::vector<TrajectoryEvent> events;  // in time order; the last one ends the motion
};

// Body: a, b (m; solid, I = (2/5)·m·a² about the rolling axis); rails tanθ, tan(α/2); g (m/s²);
// release at x0 with velocity v0 (m/s, > 0 away from O; 0: from rest), resistance μ ≥ 0.
TrajectoryReference SpheroidTrajectory(double a, double b, double tan_theta, double tan_half_alpha, double g,
                                       double x0, double v0, double mu, std::span<const double> xs);

}  // namespace uphill::oracle
