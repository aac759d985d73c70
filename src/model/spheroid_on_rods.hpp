// SpheroidOnRods: a spheroid on round rods of radius r > 0 (the rail lines are the rods' axes).
//
// No closed form exists for z(x) (docs/physics.md "Round rods"), so this is the one numeric contact
// solve of the model, used only when the scene needs it (a non-spherical body on rods; a sphere
// on rods is the closed form of a sphere of radius R + r).
//
// Method: the normal-angle parametrisation. Let n(β) be the outward unit normal of the body at
// the contact; it is perpendicular to the rail direction d = (1, T, B), so
//   n(β) = cosβ·u + sinβ·v,  u = (−T, 1, 0)/sqrt(1 + T²),  v = (B, T·B, −(1 + T²))/(|u×d|…),
// β = 0 being the fall-off (horizontal normal, contact level with the centre). The surface point
// with normal n is S = (a²n_x, b²n_y, a²n_z)/sqrt(a²n_x² + b²n_y² + a²n_z²) from the centre, and
// the rod axis passes through C + S + r·n, which must lie on the rail line (t, t·T, t·B). That
// gives the centre explicitly:  t = (S_y + r·n_y)/T,  x = t − S_x − r·n_x,  z = t·B − S_z − r·n_z.
// The slope follows from the contact normal alone, z'(x) = −n_x/n_z, so x_eq (n_x = 0) and
// x_rest(μ) (n_x = μ·n_z) are closed form; only z(x) at a given x needs a 1-D root solve of
// x(β) = x (Newton with bracketing, Boost.Math, derivative by ceres::Jet).
//
// Accuracy: x_eq, x_max, x_rest within a few ulp; At(x) to the solver's full precision (a few
// ulp in β, amplified only by the conditioning of the value itself, e.g. near x_max). Within
// 1e-9·x_max of x_max, where x(β) is flat and Newton's β would be rounding noise, β comes from
// the expansion x_max − x(β) = k0·β² + k1·β³ instead (~1e-8 relative in β): z' keeps its
// magnitude ~ 1/sqrt(x_max − x) up to the last double below x_max, and z its conditioning-level
// error (tests/model_property_test.cpp compares with the sphere-on-rods closed form there).
// Tested against the 60-digit reference and, for r → 0, against SpheroidOnLineRails.
#pragma once

#include "model/spheroid_on_line_rails.hpp"

namespace uphill {

class SpheroidOnRods {
 public:
  // a, b > 0 (semi-axes as in SpheroidOnLineRails), r > 0 the rod radius.
  SpheroidOnRods(double a, double b, double tan_theta, double tan_half_alpha, double rod_radius);

  double x_max() const { return x_max_; }
  double x_eq() const { return x_eq_; }
  double z_eq() const { return z_eq_; }
  // Smallest x for which the solver is valid (the contact on the rod axis at t = 0 or the
  // end of the monotone branch of x(β), whichever comes first).
  double x_low() const { return x_low_; }
  // Farthest rest position for rolling-resistance coefficient mu (mu < 0: nearest).
  double RestX(double mu) const;
  SpheroidPathPoint<double> At(double x) const;
  // The centre (x, z) for a contact normal at angle beta (see above); exposed for tests.
  void CentreAtNormalAngle(double beta, double* x, double* z) const;

  // --- The path in the normal angle β (for the equation of motion, src/motion) --------------
  // β is a smooth coordinate along the whole path, through the fall-off β = 0 (where dx/dβ = 0
  // and z(x) turns vertical): x, z and R* (centre to the true contact, in the x–z plane) with
  // their derivatives in β, in closed form (n'' = −n for the unit normal n(β) = cosβ·u + sinβ·v,
  // then the quotient rule through S = D·n/|D^½·n|, D = diag(a², b², a²)); no root solve, so
  // they carry only a few ulp of rounding, no solver noise. Domain: 0 ≤ β ≤ normal_angle_low().
  struct NormalAnglePoint {
    double x, z;        // centre
    double dx, dz;      // d/dβ
    double ddx, ddz;    // d²/dβ²
    double r_star, dr_star;
  };
  NormalAnglePoint PathAtNormalAngle(double beta) const;
  // β of the centre at x (x_low ≤ x ≤ x_max), as At() solves it (0 at x_max).
  double NormalAngleOf(double x) const { return x >= x_max_ ? 0.0 : BetaOf(x); }
  // β at X, in closed form (the normal ∝ (0, B/T, −1) there).
  double NormalAngleAtEquilibrium() const;
  // β at x_low (the end of the branch used).
  double normal_angle_low() const { return beta_low_; }

 private:
  // Centre for a given (not necessarily unit) normal with n·d = 0.
  void CentreForNormal(double nx, double ny, double nz, double* x, double* z) const;
  double BetaOf(double x) const;
  // β of a point near the fall-off from the expansion x_max − x(β) = k0·β² + k1·β³.
  double FallOffBeta(double x) const;

  double a_, b_, B_, T_, r_;
  double x_max_, x_eq_, z_eq_, x_low_, beta_low_;
  double fall_k0_, fall_k1_;  // x_max − x(β) = k0·β² + k1·β³ + O(β⁴) at the fall-off
};

}  // namespace uphill
