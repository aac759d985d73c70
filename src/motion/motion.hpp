// Motion: the rolling motion of the body of a Scene released at x0 (PHYSICS.md "Energy").
//
// Model: pure rolling at both contacts, one degree of freedom (the centre's x), energy
//   ½·v²·K(x) + g·z(x) = const,   K = 1 + I/(m·R*²),
// optionally with rolling resistance μ as a slope threshold (PHYSICS.md "Rolling resistance"):
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
//               w interval; double cone with x = x_t + s²; spheroid on rods (numeric path) in x
//               with x = x0 + (x_end − x0)·sin²φ (removes the release and fall-off 1/sqrt
//               singularities). Integrals by adaptive Gauss–Kronrod (Boost.Math), x(t) by
//               bracketed Newton on t(w). μ must be 0.
//  kOde         the Euler–Lagrange equation m(q)·q̈ + ½·m'(q)·q̇² = −g·z'(q) − g·μ·|x'(q)|·sgn q̇
//               in a smooth coordinate q (q = ψ − ψ0 for sphere/spheroid, q = x for the cone),
//               integrated by Boost.Odeint's Dormand–Prince 5(4) with dense output; events
//               (fall-off, reaching O, turning point, rest, a position) located by TOMS 748 on
//               the dense output. Not available for a spheroid on rods (InputError).
//
// Accuracy (tests/motion_reference_test.cpp against 25-digit references; both methods at the
// default tolerance 1e-13): t(x), x(t) within max(1e-10, 16·cond·1.1e-16) relative, cond the
// value's condition number; in practice a few 1e-13 except where cond is large (release close
// to X: cond(t) ≈ x0/((x0 − X)·λ·t)). Exception: a spheroid on rods (numeric path, whose z has
// a few ulp of solver noise that the height drop amplifies near the release): ~1e-7 relative,
// tested to 1e-7. Energy is conserved along a μ = 0 trajectory to 1e-12
// relative; time reversal returns to the start.
//
// Hard cases (tests/motion_property_test.cpp): x0 within 1e-9 of X (escape time
// ≈ ln(1/(x0 − X))/λ), motion up to x_max where the path turns vertical (t(x_max) is finite
// and returned), θ = 0, α → 0, sizes from micrometres to kilometres, the double cone (time to the
// apex diverges logarithmically: it is never reached, TimeAt(x_fall) = +∞).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/scene.hpp"

namespace uphill {

enum class MotionMethod { kQuadrature, kOde };

struct MotionOptions {
  // Initial velocity of the centre, m/s: its speed, signed by the direction of x (> 0 away
  // from O). 0: released from rest.
  double v0 = 0.0;
  double g = 9.80665;  // m/s², > 0
  double mu = 0.0;     // rolling resistance (slope threshold), ≥ 0; > 0 needs kOde
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
  // x0 outside [x_low, x_max] (x_fall excluded for the cone), g ≤ 0, μ < 0, μ > 0 with
  // kQuadrature, a spheroid on rods with kOde, v0 ≠ 0 or μ > 0 for a spheroid on rods.
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

// Fast path for a whole trajectory: the times at which a sphere or spheroid on line rails,
// released from rest at x0 (beyond X), reaches the increasing positions xs (x0 < xs[i] ≤
// x_max), by the quadrature of Motion (same substitution ψ − ψ0 = u0·cosh w) with a fixed
// Boost Gauss–Legendre rule of `nodes` points (2 … 10) on each interval between consecutive
// positions, accumulated. No error control: the accuracy of a node count for a given problem is
// what `uphill bench motion` measures (for its spheroid, 4 nodes give ~1e-13). Throws
// InputError for other scenes, x0 ≤ X, or positions that are not increasing in (x0, x_max].
std::vector<double> ReleaseTimes(const Scene& scene, double x0, const std::vector<double>& xs, double g,
                                 int nodes);

}  // namespace uphill
