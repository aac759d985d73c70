// SpheroidOnLineRails: closed forms for a spheroid (and a sphere, a = b = R) on line rails.
//
// Notation of docs/physics.md "Spheroid on line rails": A = (a/b)·tan(α/2), B = tanθ, P = 1 + A² + B². The centre path is an
// arc of an ellipse; with the ellipse parameter ψ, x = x_max·sinψ, every quantity is a short
// expression in ψ with no cancellation:
//   z(x)   = z_eq·cos(ψ − ψ0)                      z_eq = a·sqrt(A² + B²)/A
//   z'(x)  = −z_eq·sin(ψ − ψ0)/(x_max·cosψ)         ψ0 = atan2(B, A·sqrt(P))
//   R*²    = a²·(cos²(ψ + γ) + (A²/P)·sin²(ψ + γ))  γ = atan2(A·B, sqrt(P))
//   x_M    = a·sin(ψ + γ)/(A·cosγ·sqrt(1 + A²))
//   x_max  = sqrt(a² + (b/tan(α/2))²)   (fall-off: contact level with the centre, z' → −∞)
//   x_eq   = a·B/(A·sqrt(A² + B²))        (unstable equilibrium, the maximum of z: "X")
//   x_rest(μ) = x_max·K/sqrt(P·A² + K²),  K = B + μ(1 + A²)   (farthest rest, |z'| ≤ μ)
// No angle is formed in At(): the angle sums are expanded with sinψ = x/x_max, cosψ and the
// cosines and sines of ψ0 and γ as algebraic ratios,
//   cos(ψ − ψ0) = cosψ·cosψ0 + sinψ·sinψ0,   sin(ψ − ψ0) = sinψ·cosψ0 − cosψ·sinψ0,
//   cos(ψ + γ)  = cosψ·cosγ − sinψ·sinγ,     sin(ψ + γ)  = sinψ·cosγ + cosψ·sinγ,
// and cosψ = sqrt(((x_max − x)/x_max)·(1 + x/x_max)), x_max − x exact (Sterbenz) near x_max.
// (Why not ψ = atan2(sinψ, cosψ) and sin(ψ − ψ0), cos(ψ + γ) of angle differences, with
// 1 − x/x_max after rounding x/x_max: near the fall-off, where ψ and, for small α, ψ0 both
// approach π/2, those lose the digits of π/2 − ψ: z' at x_max·(1 − 1e-12) would be wrong by
// ~1e-4 relative, z' at x_max·(1 − 1e-6) with θ ≈ 90° and α = 1e-8 by ~4e-14, and z at the last
// double below x_max by ~3e-9, none of it due to the conditioning of the value.)
//
// Accuracy (binary64, tests/model_reference_test.cpp against 60-digit references and
// tests/model_property_test.cpp against 113-bit evaluations at random points): x_eq, x_max,
// z_eq, x_rest within a few ulp; z, z', R*, x_M within 16·u·(|f| + Σ_p |p·∂f/∂p| + |∂f/∂x|·x_max)
// (u = 2^-53, p = a, b, tanθ, tan(α/2)): a few ulp times the condition number of the value
// itself, large only where the value is ill-conditioned (z' near x_max or near x_eq, x_rest_low
// when B ≈ μ(1 + A²)). For the x given, z' keeps its relative accuracy up to the last double
// below x_max, where it is finite; at x_max it is −∞.
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
    using std::hypot;
    using std::sqrt;
    A_ = a * tan_half_alpha / b;
    B_ = tan_theta;
    P_ = 1.0 + A_ * A_ + B_ * B_;
    const T sqrt_p = sqrt(P_);
    a_sqrt_p_ = A_ * sqrt_p;
    x_max_ = hypot(a, b / tan_half_alpha);
    const T hypot_ab = hypot(A_, B_);
    z_eq_ = a * (hypot_ab / A_);  // = a exactly at θ = 0
    x_eq_ = a * B_ / (A_ * hypot_ab);
    const T h = hypot(a_sqrt_p_, B_);
    cos_psi0_ = a_sqrt_p_ / h;
    sin_psi0_ = B_ / h;
    const T hg = hypot(A_ * B_, sqrt_p);
    cos_gamma_ = sqrt_p / hg;
    sin_gamma_ = A_ * B_ / hg;
    contact_scale_ = a / (A_ * cos_gamma_ * sqrt(1.0 + A_ * A_));
  }

  const T& A() const { return A_; }
  const T& P() const { return P_; }
  const T& x_max() const { return x_max_; }
  const T& x_eq() const { return x_eq_; }
  const T& z_eq() const { return z_eq_; }
  // Smallest x at which the contact is still on the rails (t ≥ 0): −x_max·sinγ ≤ 0.
  T x_low() const { return -x_max_ * sin_gamma_; }
  // x_max − x_eq = x_max·cos²ψ0/(1 + sinψ0), without the cancellation of the difference.
  T FallOffMargin() const {
    return x_max_ * cos_psi0_ * cos_psi0_ / (1.0 + sin_psi0_);
  }
  // Farthest rest position for rolling-resistance coefficient mu (mu < 0 gives the nearest one,
  // which may be negative: off the rails). |x_rest| ≤ x_max always (the ratio is formed first
  // and clamped to 1: x_max·K/hypot(·, K) could round one ulp beyond x_max when K ≫ A·sqrt(P)).
  T RestX(const T& mu) const {
    using std::hypot;
    const T k = B_ + mu * (1.0 + A_ * A_);
    T ratio = k / hypot(a_sqrt_p_, k);
    if (ratio > 1.0) ratio = T(1.0);
    if (ratio < -1.0) ratio = T(-1.0);
    return x_max_ * ratio;
  }
  // Ellipse parameter ψ of position x and cosψ; x must lie in [x_low, x_max].
  void Psi(const T& x, T* psi, T* cos_psi) const {
    using std::atan2;
    *cos_psi = CosPsi(x);
    *psi = atan2(x / x_max_, *cos_psi);
  }
  SpheroidPathPoint<T> At(const T& x) const {
    using std::sqrt;
    const T sin_psi = x / x_max_;
    const T cos_psi = CosPsi(x);
    const T cw = cos_psi * cos_gamma_ - sin_psi * sin_gamma_;  // cos(ψ + γ)
    const T sw = sin_psi * cos_gamma_ + cos_psi * sin_gamma_;  // sin(ψ + γ)
    SpheroidPathPoint<T> p;
    // cos(ψ − ψ0): two non-negative terms for x ≥ 0, so z keeps full relative accuracy even
    // where ψ − ψ0 ≈ π/2 (θ → 0 near the fall-off).
    p.z = z_eq_ * (cos_psi * cos_psi0_ + sin_psi * sin_psi0_);
    // −sin(ψ − ψ0)/cosψ = sinψ0 − tanψ·cosψ0: the difference vanishes at x_eq only (there its
    // rounding is that of x), and at x_max the second term is +∞, so z' = −∞, not NaN.
    p.dzdx = z_eq_ * (sin_psi0_ - sin_psi * cos_psi0_ / cos_psi) / x_max_;
    p.r_star = a_ * sqrt(cw * cw + (A_ * A_ / P_) * sw * sw);
    p.x_contact = contact_scale_ * sw;
    return p;
  }

 private:
  // cosψ = sqrt(1 − (x/x_max)²) as sqrt(((x_max − x)/x_max)·(1 + x/x_max)): x_max − x is exact
  // for x ≥ x_max/2, so cosψ has full relative accuracy up to the last double below x_max.
  T CosPsi(const T& x) const {
    using std::sqrt;
    T one_minus = (x_max_ - x) / x_max_;
    if (one_minus < 0.0) one_minus = T(0.0);  // x beyond x_max by rounding
    return sqrt(one_minus * (1.0 + x / x_max_));
  }
  T a_, A_, B_, P_, a_sqrt_p_, x_max_, z_eq_, x_eq_, cos_psi0_, sin_psi0_, cos_gamma_,
      sin_gamma_, contact_scale_;
};

}  // namespace uphill
