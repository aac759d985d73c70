// SpheroidOnLineRails: closed forms for a spheroid (and a sphere, a = b = R) on line rails.
//
// Notation of PHYSICS.md: A = (a/b)·tan(α/2), B = tanθ, P = 1 + A² + B². The centre path is an
// arc of an ellipse; with the ellipse parameter ψ, x = x_max·sinψ, every quantity is a short
// expression in ψ with no cancellation:
//   z(x)   = z_eq·cos(ψ − ψ0)                      z_eq = a·sqrt(A² + B²)/A
//   z'(x)  = −z_eq·sin(ψ − ψ0)/(x_max·cosψ)         ψ0 = atan2(B, A·sqrt(P))
//   R*²    = a²·(cos²(ψ + γ) + (A²/P)·sin²(ψ + γ))  γ = atan2(A·B, sqrt(P))
//   x_M    = a·sin(ψ + γ)/(A·cosγ·sqrt(1 + A²))
//   x_max  = sqrt(a² + (b/tan(α/2))²)   (fall-off: contact level with the centre, z' → −∞)
//   x_eq   = a·B/(A·sqrt(A² + B²))        (unstable equilibrium, the maximum of z: "X")
//   x_rest(μ) = x_max·K/sqrt(P·A² + K²),  K = B + μ(1 + A²)   (farthest rest, |z'| ≤ μ)
// cosψ is formed as sqrt((1 − x/x_max)(1 + x/x_max)), the factor that vanishes at x_max
// being exact by Sterbenz's lemma, so points within 1e-12 of x_max keep their digits.
//
// Accuracy (binary64, tests/model_reference_test.cpp against 60-digit references): x_eq, x_max,
// z_eq, x_rest within a few ulp; z, z', R*, x_M within 16·cond·1.1e-16 where cond is the
// condition number of the value itself (large only where the value is ill-conditioned: z' near
// x_max or near x_eq, x_rest_low when B ≈ μ(1 + A²)).
//
// Domain: x_low ≤ x ≤ x_max with x_low = −x_max·sinγ (below it the contact would be at t < 0).
// Members are plain data; the class is templated on the scalar so that ceres::Jet carries
// first-order uncertainty propagation through the same code.
#pragma once

#include <cmath>

namespace uphill {

template <typename T>
struct SpheroidPathPoint {
  T z, dzdx, r_star, x_contact;
};

template <typename T>
class SpheroidOnLineRails {
 public:
  // a: semi-axis in x and z; b: semi-axis along y; both > 0. tan_theta ≥ 0, tan_half_alpha > 0.
  SpheroidOnLineRails(const T& a, const T& b, const T& tan_theta, const T& tan_half_alpha) : a_(a) {
    using std::atan2;
    using std::hypot;
    using std::sqrt;
    A_ = a * tan_half_alpha / b;
    B_ = tan_theta;
    P_ = 1.0 + A_ * A_ + B_ * B_;
    const T sqrt_p = sqrt(P_);
    a_sqrt_p_ = A_ * sqrt_p;
    x_max_ = hypot(a, b / tan_half_alpha);
    const T hypot_ab = hypot(A_, B_);
    z_eq_ = a * hypot_ab / A_;
    x_eq_ = a * B_ / (A_ * hypot_ab);
    psi0_ = atan2(B_, a_sqrt_p_);
    const T h = hypot(a_sqrt_p_, B_);
    cos_psi0_ = a_sqrt_p_ / h;
    sin_psi0_ = B_ / h;
    gamma_ = atan2(A_ * B_, sqrt_p);
    contact_scale_ = a / (A_ * cos_(gamma_) * sqrt(1.0 + A_ * A_));
  }

  const T& A() const { return A_; }
  const T& P() const { return P_; }
  const T& x_max() const { return x_max_; }
  const T& x_eq() const { return x_eq_; }
  const T& z_eq() const { return z_eq_; }
  // Smallest x at which the contact is still on the rails (t ≥ 0): −x_max·sinγ ≤ 0.
  T x_low() const {
    using std::sin;
    return -x_max_ * sin(gamma_);
  }
  // x_max − x_eq = x_max·cos²ψ0/(1 + sinψ0), without the cancellation of the difference.
  T FallOffMargin() const {
    using std::sin;
    return x_max_ * cos_psi0_ * cos_psi0_ / (1.0 + sin_psi0_);
  }
  // Farthest rest position for rolling-resistance coefficient mu (mu < 0 gives the nearest one,
  // which may be negative: off the rails).
  T RestX(const T& mu) const {
    using std::hypot;
    const T k = B_ + mu * (1.0 + A_ * A_);
    return x_max_ * k / hypot(a_sqrt_p_, k);
  }
  // Ellipse parameter ψ of position x and cosψ; x must lie in [x_low, x_max].
  void Psi(const T& x, T* psi, T* cos_psi) const {
    using std::atan2;
    using std::sqrt;
    const T r = x / x_max_;
    T one_minus = 1.0 - r;
    if (one_minus < 0.0) one_minus = T(0.0);  // x = x_max to within rounding
    *cos_psi = sqrt(one_minus * (1.0 + r));
    *psi = atan2(r, *cos_psi);
  }
  SpheroidPathPoint<T> At(const T& x) const {
    using std::sin;
    using std::sqrt;
    T psi, cos_psi;
    Psi(x, &psi, &cos_psi);
    const T u = psi - psi0_;
    const T w = psi + gamma_;
    const T cw = cos_(w), sw = sin(w);
    SpheroidPathPoint<T> p;
    // cos(ψ − ψ0) = cosψ·cosψ0 + sinψ·sinψ0: two non-negative terms for x ≥ 0, so z keeps
    // full relative accuracy even where ψ − ψ0 ≈ π/2 (θ → 0 near the fall-off).
    p.z = z_eq_ * (cos_psi * cos_psi0_ + (x / x_max_) * sin_psi0_);
    p.dzdx = -z_eq_ * sin(u) / (x_max_ * cos_psi);
    p.r_star = a_ * sqrt(cw * cw + (A_ * A_ / P_) * sw * sw);
    p.x_contact = contact_scale_ * sw;
    return p;
  }

 private:
  static T cos_(const T& v) {
    using std::cos;
    return cos(v);
  }
  T a_, A_, B_, P_, a_sqrt_p_, x_max_, z_eq_, x_eq_, psi0_, cos_psi0_, sin_psi0_, gamma_,
      contact_scale_;
};

}  // namespace uphill
