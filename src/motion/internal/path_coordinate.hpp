// Internal to src/motion: the centre path in a smooth generalised coordinate q, with everything
// the two motion methods need (position, height, tangent, R*, the effective mass and its
// derivative). Not part of the public API (see motion.hpp).
//
//   Ellipse (sphere, spheroid on line rails; sphere on rods as a sphere of radius R + r):
//     q = u = ψ − ψ0, the ellipse parameter measured from the equilibrium X (docs/physics.md
//     "Stable forms"): x = x_max·sin(ψ0 + u), z = z_eq·cos u. Measuring from ψ0 keeps full
//     relative accuracy in u when the release is within 1e-9 of X (the escape time depends on
//     ln u0). Range u_low = −γ − ψ0 (contact at O) … u_max = π/2 − ψ0 (fall-off, x_max); the
//     path is analytic across both, so nothing in q is singular.
//   Line (double cone): q = x, z = A − B·x, R* = c·(x_fall − x); R* → 0 at the apex.
//
// Kinetic energy per unit mass ½·m(q)·q̇², m = K·(x'² + z'²), K = 1 + I/(m_body·R*²); potential
// g·z(q). Derivatives ' are d/dq.
#pragma once

#include <cmath>

#include "model/scene.hpp"

namespace uphill::internal {

struct Geometry {
  double x, z;       // centre
  double dx, dz;     // dx/dq, dz/dq
  double metric;     // M = dx² + dz² (speed² = M·q̇²)
  double r_star;     // distance from the centre to the instantaneous axis (true contact)
  double kinetic;    // K = 1 + I/(m R*²)
  double mass;       // m = K·M
  double dmass;      // dm/dq
};

// Ellipse form of a sphere or spheroid path (line rails, or a sphere on rods).
class EllipseCoordinate {
 public:
  // a, b: semi-axes of the enlarged body (a = b = R + r for a sphere on rods); inertia: I/(m·a_true²)
  // with a_true = shrink·a the real body's across size.
  EllipseCoordinate(double a, double b, double tan_theta, double tan_half_alpha, double inertia) {
    const double A = a * tan_half_alpha / b, B = tan_theta;
    const double P = 1.0 + A * A + B * B, sqrt_p = std::sqrt(P);
    x_max_ = std::hypot(a, b / tan_half_alpha);
    z_eq_ = a * (std::hypot(A, B) / A);
    const double h = std::hypot(A * sqrt_p, B);
    c0_ = A * sqrt_p / h;
    s0_ = B / h;
    const double hg = std::hypot(A * B, sqrt_p);
    cg_ = sqrt_p / hg;
    sg_ = A * B / hg;
    q_ = A * A / P;
    inertia_ = inertia;
    a_ = a;
    u_max_ = std::atan2(c0_, s0_);             // π/2 − ψ0
    u_low_ = -std::atan2(sg_ * c0_ + cg_ * s0_, cg_ * c0_ - sg_ * s0_);  // −(γ + ψ0)
  }
  double x_max() const { return x_max_; }
  double z_eq() const { return z_eq_; }
  double u_max() const { return u_max_; }
  double u_low() const { return u_low_; }
  // sin/cos of ψ0 (the ellipse parameter of X) and of γ, q = A²/P, and I/(m·a_true²).
  double sin_psi0() const { return s0_; }
  double cos_psi0() const { return c0_; }
  double sin_gamma() const { return sg_; }
  double cos_gamma() const { return cg_; }
  double q() const { return q_; }
  double inertia() const { return inertia_; }

  // u of a position x on the path (x_low ≤ x ≤ x_max), without forming ψ0 + u.
  double UOfX(double x) const {
    const double sp = x / x_max_;
    double om = (x_max_ - x) / x_max_;
    if (om < 0.0) om = 0.0;
    const double cp = std::sqrt(om * (1.0 + sp));
    return std::atan2(sp * c0_ - cp * s0_, cp * c0_ + sp * s0_);
  }
  double XOfU(double u) const {
    return x_max_ * (std::sin(u) * c0_ + std::cos(u) * s0_);
  }
  // z(x0) − z(u) for a release at u0, without cancellation: 2·z_eq·sin((u+u0)/2)·sin((u−u0)/2).
  double Drop(double u0, double u) const {
    return 2.0 * z_eq_ * std::sin(0.5 * (u + u0)) * std::sin(0.5 * (u - u0));
  }
  // dz/dx at u (−∞ at the fall-off).
  double Slope(double u) const {
    const double su = std::sin(u), cu = std::cos(u);
    const double cp = cu * c0_ - su * s0_;
    return -z_eq_ * su / (x_max_ * cp);
  }

  Geometry At(double u) const {
    const double su = std::sin(u), cu = std::cos(u);
    const double sp = su * c0_ + cu * s0_;  // sinψ
    const double cp = cu * c0_ - su * s0_;  // cosψ
    const double cw = cp * cg_ - sp * sg_;  // cos(ψ + γ)
    const double sw = sp * cg_ + cp * sg_;  // sin(ψ + γ)
    Geometry g;
    g.x = x_max_ * sp;
    g.z = z_eq_ * cu;
    g.dx = x_max_ * cp;
    g.dz = -z_eq_ * su;
    g.metric = g.dx * g.dx + g.dz * g.dz;
    const double d = cw * cw + q_ * sw * sw;  // R*²/a²
    g.r_star = shrink_ * a_ * std::sqrt(d);
    // K = 1 + I/(m R*²) with I/m = inertia·(shrink·a)², R* = shrink·a·sqrt(d): 1 + inertia/d.
    g.kinetic = 1.0 + inertia_ / d;
    const double dd = 2.0 * (q_ - 1.0) * sw * cw;
    const double dk = -inertia_ * dd / (d * d);
    const double dm = 2.0 * (-x_max_ * x_max_ * cp * sp + z_eq_ * z_eq_ * su * cu);
    g.mass = g.kinetic * g.metric;
    g.dmass = dk * g.metric + g.kinetic * dm;
    return g;
  }
  void set_shrink(double s) { shrink_ = s; }

 private:
  double x_max_, z_eq_, c0_, s0_, cg_, sg_, q_, inertia_, a_, u_max_, u_low_;
  double shrink_ = 1.0;
};

// Straight path of the double cone, q = x.
class LineCoordinate {
 public:
  explicit LineCoordinate(const Scene& scene) {
    const auto& cone = *scene.cone();
    a_ = cone.A();
    b_ = cone.B();
    x_fall_ = cone.x_fall();
    x_low_ = cone.x_low();
    // R* = slope·(x_fall − x): read the slope off the model at x_low (exact linear form).
    r_slope_ = cone.RStar(x_low_) / (x_fall_ - x_low_);
    inertia_ = scene.body().InertiaFactor() * scene.body().across * scene.body().across;
  }
  double B() const { return b_; }
  double x_fall() const { return x_fall_; }
  double x_low() const { return x_low_; }
  Geometry At(double x) const {
    Geometry g;
    g.x = x;
    g.z = a_ - b_ * x;
    g.dx = 1.0;
    g.dz = -b_;
    g.metric = 1.0 + b_ * b_;
    const double gap = x_fall_ - x;
    g.r_star = r_slope_ * gap;
    const double c = inertia_ / (r_slope_ * r_slope_);  // I/(m R*²) = c/gap²
    g.kinetic = 1.0 + c / (gap * gap);
    g.mass = g.kinetic * g.metric;
    g.dmass = 2.0 * c / (gap * gap * gap) * g.metric;
    return g;
  }

 private:
  double a_, b_, x_fall_, x_low_, r_slope_, inertia_;
};

// Spheroid on round rods (the numeric contact path, SpheroidOnRods): q = β_X − β, β the contact
// normal angle (PathAtNormalAngle), measured from the equilibrium X so that q grows with x.
// The path is explicit in β (no root solve, no solver noise), smooth through the fall-off
// q_max = β_X (β = 0, where dx/dq = 0 and the path in x turns vertical) down to x_low.
class RodsCoordinate {
 public:
  explicit RodsCoordinate(const Scene& scene)
      : path_(scene.body().across, scene.body().along, scene.rails().tan_theta, scene.rails().tan_half_alpha,
              scene.rod_radius()),
        beta_eq_(path_.NormalAngleAtEquilibrium()),
        inertia_(scene.body().InertiaFactor() * scene.body().across * scene.body().across) {}
  double q_max() const { return beta_eq_; }
  double q_low() const { return beta_eq_ - path_.normal_angle_low(); }
  double QOfX(double x) const { return beta_eq_ - path_.NormalAngleOf(x); }
  double XOfQ(double q) const { return path_.PathAtNormalAngle(beta_eq_ - q).x; }
  Geometry At(double q) const {
    const SpheroidOnRods::NormalAnglePoint p = path_.PathAtNormalAngle(beta_eq_ - q);
    Geometry g;
    g.x = p.x;
    g.z = p.z;
    g.dx = -p.dx;  // d/dq = −d/dβ
    g.dz = -p.dz;
    g.metric = p.dx * p.dx + p.dz * p.dz;
    g.r_star = p.r_star;
    const double c = inertia_ / (p.r_star * p.r_star);  // I/(m R*²)
    g.kinetic = 1.0 + c;
    // dK/dq = 2·c·R*'_β/R*, dM/dq = −2·(x'x'' + z'z'')_β.
    const double dk = 2.0 * c * p.dr_star / p.r_star;
    const double dm = -2.0 * (p.dx * p.ddx + p.dz * p.ddz);
    g.mass = g.kinetic * g.metric;
    g.dmass = dk * g.metric + g.kinetic * dm;
    return g;
  }

 private:
  SpheroidOnRods path_;  // the same construction as the Scene's (which does not expose its own)
  double beta_eq_, inertia_;
};

}  // namespace uphill::internal
