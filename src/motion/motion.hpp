// Motion: the rolling motion of the body of a Scene released at x0 (docs/physics.md "Energy").
//
// Model: pure rolling at both contacts, one degree of freedom (the centre's x), energy
//   ½·v²·K(x) + g·z(x) = const,   K = 1 + I/(m·R*²),
// optionally with rolling resistance μ as a slope threshold (docs/physics.md "Rolling resistance"):
// a resisting force that does work g·μ per metre of horizontal travel, so the body stays at rest
// where |z'(x)| ≤ μ. Direction from the physics: released at rest beyond X the body rolls away
// from O (up the rails, its centre going down), below X it rolls back toward O; exactly at X it
// stays. With an initial velocity it may first climb to a turning point.
//
// Units: SI throughout (m, s, m/s, rad). x0 must lie in [x_low, x_max] of the scene.
//
// Two independent methods (MotionOptions::method), which agree to their tolerances:
//  kQuadrature  t(x) = ∫dx/ẋ from energy conservation, each singularity removed analytically:
//               sphere/spheroid with ψ − ψ0 = u_t·cosh w (u_t the rest or turning point, ψ the
//               ellipse parameter), which makes dt/dw = sqrt(K·M/(g·z_eq·sinc(u_t·cosh²(w/2))·
//               sinc(u_t·sinh²(w/2)))) smooth and bounded from the release through the fall-off
//               (M = |dC/dψ|²), and turns the ln(1/(x0 − X)) escape time into the length of the
//               w interval; double cone with x = x_t + s²; spheroid on rods in its contact-normal
//               coordinate q = β_X − β (below) with q = q0·cosh w as for the ellipse, the height
//               drop z(q0) − z(q) from the explicit path (near the release as −∫dz/dq by
//               Gauss–Legendre, not as a difference of heights). Integrals by adaptive
//               Gauss–Kronrod (Boost.Math), x(t) by bracketed Newton on t(w). μ must be 0, and
//               v0 must be 0 for a spheroid on rods (use kOde).
//  kOde         the Euler–Lagrange equation m(q)·q̈ + ½·m'(q)·q̇² = −g·z'(q) − g·μ·|x'(q)|·sgn q̇
//               in a smooth coordinate q (q = ψ − ψ0 for sphere/spheroid, q = x for the cone,
//               q = β_X − β for a spheroid on rods), integrated ONCE, in the constructor, by
//               Boost.Odeint's Dormand–Prince 5(4) (std::array state: no allocation per step),
//               keeping every step's dense output (Odeint's 4th-order continuous extension);
//               events (fall-off, reaching O, turning point, rest) and TimeAt's positions located
//               by TOMS 748 on it, At(t) evaluates it: each query costs a binary search over the
//               steps and a few polynomial evaluations, never a new integration. Every scene, any
//               v0, μ ≥ 0.
//
// Spheroid on round rods: no closed form z(x), but the path is explicit in the contact normal's
// angle β (SpheroidOnRods::PathAtNormalAngle: x, z, R* and their β-derivatives in closed form,
// smooth through the fall-off β = 0 where z(x) turns vertical). Only converting a position x to
// β needs a root solve (TimeAt(x), AtPosition(x), x0); the equation of motion and the quadrature
// run in β, so no solver noise enters dz/dq or m'(q).
//
// Accuracy (tests/motion_reference_test.cpp against 25-digit references; both methods at the
// default tolerance 1e-13): t(x), x(t) within max(1e-10, 16·cond·1.1e-16) relative, cond the
// value's condition number; in practice a few 1e-13 except where cond is large (release close
// to X: cond(t) ≈ x0/((x0 − X)·λ·t)). The same holds for a spheroid on rods (both methods; the
// two agree to ~1e-12, and at a = b with the sphere-on-rods closed form to 1e-11), except for a
// release very close to X, where dz/dq ∝ q is formed from O(1) terms: the quadrature is then
// limited to ~4e-17/|q0| relative (3e-12 measured at x0 − X = 1e-6·(x_max − X)). Energy is
// conserved along a μ = 0 trajectory to 1e-12 relative; time reversal returns to the start.
// kOde at a looser tolerance: the times' largest relative error stays below the tolerance
// (0.2–0.9 of it measured, 1e-6 … 1e-12, on a release, a throw that turns and a throw that comes
// to rest: tests/motion_trajectory_test.cpp, `uphill bench motion`); it is not a bound (the
// control is per step).
//
// Hard cases (tests/motion_property_test.cpp): x0 within 1e-9 of X (escape time
// ≈ ln(1/(x0 − X))/λ), motion up to x_max where the path turns vertical (t(x_max) is finite
// and returned), θ = 0, α → 0, sizes from micrometres to kilometres, the double cone (time to the
// apex diverges logarithmically: it is never reached, TimeAt(x_fall) = +∞).
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "model/vector_kernel.hpp"

namespace uphill {

enum class MotionMethod { kQuadrature, kOde };

struct MotionOptions {
  // Initial velocity of the centre, m/s: its speed, signed by the direction of x (> 0 away
  // from O). 0: released from rest. At most 1000 m/s in size (model/input_ranges.hpp).
  double v0 = 0.0;
  double g = 9.80665;  // m/s², in [1e-3, 1e3] (model/input_ranges.hpp)
  double mu = 0.0;     // rolling resistance (slope threshold), in [0, 10]; > 0 needs kOde
  MotionMethod method = MotionMethod::kQuadrature;
  // Relative accuracy target of t and x, in [1e-15, 1e-2]. 1e-13 by default.
  double tolerance = 1e-13;
};

// The state at time t. v is the speed of the centre (≥ 0); vx, vz its components; angle the
// rotation about the rolling axis (y) since release, rad, ∫ω_y dt (positive while x grows).
struct MotionSample {
  double t = 0, x = 0, z = 0, v = 0, vx = 0, vz = 0, angle = 0;
};

enum class MotionEventKind {
  kFallOff,       // reaches x_max: the contact is level with the centre, it drops between the rails
  kReachesO,      // reaches x_low: the contact reaches the rails' meeting point O (rolling back)
  kTurningPoint,  // velocity zero, reverses
  kRest,          // comes to rest for good (μ > 0: |z'| ≤ μ at zero speed; or released at X)
  kPosition,      // a requested position (Motion::PositionEvent)
};
// "falls off", "reaches O", "turning point", "comes to rest", "position".
std::string EventName(MotionEventKind kind);

struct MotionEvent {
  MotionEventKind kind;
  double t, x;
};

class Motion {
 public:
  // Throws InputError (naming x0, v0, g, mu, tolerance or method) for input outside the domain:
  // x0 outside [x_low, x_max] (x_fall excluded for the cone), v0, g or μ outside their ranges
  // (model/input_ranges.hpp), μ > 0 with kQuadrature, v0 ≠ 0 with kQuadrature for a spheroid on
  // rods.
  Motion(const Scene& scene, double x0, const MotionOptions& options = {});
  ~Motion();
  Motion(Motion&&) noexcept;
  Motion& operator=(Motion&&) noexcept;

  const Scene& scene() const;
  double x0() const;
  // Initial direction of x: +1 away from O, −1 toward O, 0 stays at rest.
  int direction() const;
  // Turning points and the final event (fall-off, reaching O, rest), in time order.
  const std::vector<MotionEvent>& events() const;
  // Time after which the body has left the rails' model (falls off, or its contact reaches O):
  // At() is defined on [0, end_time()]. +∞ when neither happens (cone rolling toward its apex,
  // a body that comes to rest or stays at rest: At() then gives the rest state for all later t).
  double end_time() const;
  // First time the centre is at x; +∞ if it never gets there.
  double TimeAt(double x) const;
  // The event "reaches position x" (t = +∞ if never).
  MotionEvent PositionEvent(double x) const;
  // The state at time t, 0 ≤ t ≤ end_time(); InputError ("t") otherwise.
  MotionSample At(double t) const;
  // The state when the centre first reaches x; InputError ("x") if it never does.
  MotionSample AtPosition(double x) const;

  class Engine;  // implementation (quadrature or ODE)

 private:
  std::unique_ptr<Engine> engine_;
};

// Fast path for a whole trajectory (src/motion/release_times.cpp): the times at which a sphere
// or spheroid on line rails (or a sphere on rods), released from rest at x0 (X < x0 < x_max),
// reaches the strictly increasing positions xs (x0 < xs[i] ≤ x_max). The integral of the
// quadrature method (ψ − ψ0 = u0·cosh w), written in v = sinh(w/2), by a fixed Boost
// Gauss–Legendre rule on each interval between consecutive positions, accumulated; the integrand
// is evaluated in closed form on arrays of nodes (AVX2 + glibc libmvec when the CPU has them,
// chosen at run time, else scalar libm), with no allocation but the returned vector.
//
// Node count: nodes = 0 chooses it per interval a priori from `tolerance`: dt/dv is analytic
// except at a few complex points known in closed form, and the Gauss–Legendre error of N nodes
// on an interval follows from its distance to them (Bernstein ellipse); an interval needing
// more than 12 nodes is split. nodes = 2 … 12 forces that many on every interval.
// Accuracy: the relative error of every time ≲ tolerance (an estimate, not an error control;
// tests/motion_property_test.cpp checks it on five scenes from 1e-4 to 1e-13, and
// `uphill bench motion` prints the error reached against a 50-digit reference). Throws
// InputError (naming x0, xs, g, nodes, tolerance, kernel or scene) for other scenes, x0 ≤ X,
// positions not increasing in (x0, x_max].
struct ReleaseTimesOptions {
  double g = 9.80665;        // m/s², in [1e-3, 1e3] (model/input_ranges.hpp)
  double tolerance = 1e-13;  // relative, in [1e-15, 1e-2]; used when nodes = 0
  int nodes = 0;             // 0: from the tolerance; 2 … 12: fixed
  VectorKernel kernel = VectorKernel::kAuto;  // vector_kernel.hpp
};
// Writes t[i] for xs[i]; t.size() == xs.size().
void ReleaseTimes(const Scene& scene, double x0, std::span<const double> xs, std::span<double> t,
                  const ReleaseTimesOptions& options = {});
std::vector<double> ReleaseTimes(const Scene& scene, double x0, const std::vector<double>& xs,
                                 const ReleaseTimesOptions& options = {});

}  // namespace uphill
