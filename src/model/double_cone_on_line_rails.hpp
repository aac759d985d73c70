// DoubleConeOnLineRails: closed forms for two right cones joined at their bases (base radius R,
// half-length h, axis along y) on line rails.
//
// k = R/h, s = k²·tan²(α/2), Q = 1 + tan²θ − s (Q > 0 required). The centre path is the straight
// line z = A − B·x. The paper's forms are 0/0 at s = 1; these are identical and stable:
//   A = R·(1 + tan²θ)/(sqrt(Q) + k·tanθ·tan(α/2))
//   B = (k·T − tanθ)(k·T + tanθ)/(k·T·sqrt(Q) + tanθ),   T = tan(α/2)
// Contact (double root of the paper's eq. 11): x_M = (x + tanθ·z − R·k·T)/Q; R* = R − k·T·x_M,
// evaluated as R* = k·T·(k·T + tanθ·√Q)·(x_fall − x)/(√Q·(k·T·√Q + tanθ)) (x_M is linear in x
// and reaches h/T at x_fall; 1 − tanθ·B = √Q·(k·T + tanθ·√Q)/(k·T·√Q + tanθ)): a product of
// positive factors, exactly 0 at x_fall and never negative on the path. (R − k·T·x_M cancels
// there: it gave |R*(x_fall)| up to 3e-12·R, negative in a quarter of random cases.)
// Critical inclination at fixed α: tanθ0 = k·T; it rolls up (centre descends as x grows)
// iff θ < θ0 ⇔ B > 0. At fixed 3-D opening 2φ the critical inclination is asin(tanφ·k)
// (the paper's tanθ0 = tanφ·tanψ/sqrt(1 − tan²φ·tan²ψ)), undefined when tanφ·k ≥ 1.
// Valid for x_low ≤ x < x_fall: x_fall = h/T (contact reaches the apex, R* → 0); below
// x_low = (R·k·T − tanθ·A)/(1 − tanθ·B) the cone rests on O.
//
// Accuracy: A, B, θ0 within a few ulp except where B itself is ill-conditioned (θ ≈ θ0:
// relative error ≈ cond(B)·1e-16); R* within a few ulp relative up to the apex (x_fall − x is
// exact near x_fall); x_M as written above, absolute error ~u·(|x| + tanθ·|z| + R·k·T)/Q.
#pragma once

#include <cmath>

namespace uphill {

template <typename T>
class DoubleConeOnLineRails {
 public:
  DoubleConeOnLineRails(const T& R, const T& h, const T& tan_theta, const T& tan_half_alpha)
      : R_(R), tan_theta_(tan_theta), T_(tan_half_alpha) {
    using std::sqrt;
    k_ = R / h;
    kT_ = k_ * T_;
    Q_ = 1.0 + tan_theta * tan_theta - kT_ * kT_;
    const T sqrt_q = sqrt(Q_);
    A_ = R * (1.0 + tan_theta * tan_theta) / (sqrt_q + kT_ * tan_theta);
    B_ = (kT_ - tan_theta) * (kT_ + tan_theta) / (kT_ * sqrt_q + tan_theta);
    x_fall_ = h / T_;
    x_low_ = (R * kT_ - tan_theta * A_) / (1.0 - tan_theta * B_);
    r_star_slope_ = kT_ * (kT_ + tan_theta * sqrt_q) / (sqrt_q * (kT_ * sqrt_q + tan_theta));
  }

  bool valid() const { return Q_ > 0.0; }  // otherwise the closed form does not apply
  const T& Q() const { return Q_; }
  const T& A() const { return A_; }
  const T& B() const { return B_; }
  const T& x_fall() const { return x_fall_; }
  const T& x_low() const { return x_low_; }
  T z_fall() const { return A_ - B_ * x_fall_; }
  T s() const { return kT_ * kT_; }
  T psi() const {
    using std::atan;
    return atan(k_);
  }
  T theta0() const {
    using std::atan;
    return atan(kT_);
  }
  bool rolls_up() const { return B_ > 0.0; }
  T Z(const T& x) const { return A_ - B_ * x; }
  T ContactX(const T& x) const { return (x + tan_theta_ * Z(x) - R_ * kT_) / Q_; }
  T RStar(const T& x) const { return r_star_slope_ * (x_fall_ - x); }

 private:
  T R_, tan_theta_, T_, k_, kT_, Q_, A_, B_, x_fall_, x_low_, r_star_slope_;
};

}  // namespace uphill
