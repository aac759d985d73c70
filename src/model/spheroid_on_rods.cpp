#include "model/spheroid_on_rods.hpp"

#include <ceres/jet.h>

#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "model/input_error.hpp"
#include "internal/spheroid_on_rods_closed_forms.hpp"

namespace uphill {
namespace {

// Contact geometry for the unit normal n(β) (see the header); templated for ceres::Jet.
template <typename S>
struct Contact {
  S nx, ny, nz;  // outward unit normal of the body at the contact
  S sx, sz;      // contact point on the body relative to the centre (x and z parts)
  S x, z;        // the centre
};

template <typename S>
Contact<S> ContactForNormal(const S& nx, const S& ny, const S& nz, double a, double b, double B,
                            double T, double r) {
  using std::sqrt;
  const S norm = sqrt(a * a * nx * nx + b * b * ny * ny + a * a * nz * nz);
  const S t = (b * b * ny / norm + r * ny) / T;
  Contact<S> c{nx, ny, nz, a * a * nx / norm, a * a * nz / norm, S(), S()};
  c.x = t - c.sx - r * nx;
  c.z = t * B - c.sz - r * nz;
  return c;
}

template <typename S>
Contact<S> ContactAtAngle(const S& beta, double a, double b, double B, double T, double r) {
  using std::cos;
  using std::sin;
  const double s1 = std::sqrt(1.0 + T * T);
  const double dn = std::sqrt(1.0 + T * T + B * B);
  const S c = cos(beta), s = sin(beta);
  return ContactForNormal<S>((-T * c + B * s / dn) / s1, (c + T * B * s / dn) / s1,
                             -(1.0 + T * T) * s / (dn * s1), a, b, B, T, r);
}

}  // namespace

SpheroidOnRods::SpheroidOnRods(double a, double b, double tan_theta, double tan_half_alpha,
                               double rod_radius)
    : a_(a), b_(b), B_(tan_theta), T_(tan_half_alpha), r_(rod_radius) {
  RequirePositiveFinite("rod radius", rod_radius);
  // Closed forms (docs/physics.md "Round rods"), shared with first-order propagation: spheroid_on_rods_closed_forms.hpp.
  x_max_ = SpheroidOnRodsXMax(a, b, T_, r_);
  x_eq_ = SpheroidOnRodsXEq(a, b, B_, T_, r_);
  double x_unused;
  CentreForNormal(0.0, B_ / T_, -1.0, &x_unused, &z_eq_);
  // The branch used: β from 0 (fall-off) while the contact stays at t ≥ 0 (n_y ≥ 0) and x(β)
  // keeps decreasing. n_y = 0 at β_n = π − atan(|d|/(T·B)); scan for a turning point of x(β)
  // before it (there is none for the apparatus' geometries; the scan makes the domain explicit).
  const double dn = std::sqrt(1.0 + T_ * T_ + B_ * B_);
  const double beta_n = std::numbers::pi - std::atan2(dn, T_ * B_);
  const int kScan = 256;
  beta_low_ = beta_n;
  double x_prev = x_max_;
  for (int i = 1; i <= kScan; ++i) {
    const double beta = beta_n * i / kScan;
    double xb, zb;
    CentreAtNormalAngle(beta, &xb, &zb);
    if (!(xb < x_prev)) {
      beta_low_ = beta_n * (i - 1) / kScan;
      break;
    }
    x_prev = xb;
  }
  // The fall-off expansion x_max − x(β) = k0·β² + k1·β³ + O(β⁴): k(β) = (x_max − x(β))/β² at
  // β = β1, 2β1, 3β1 (β1 = 1e-3·β_low), extrapolated to β = 0 by the quadratic through them
  // (error ~6·β1³ ≈ 6e-9 relative from the next term, ~7·2u/β1² ≈ 2e-9 from the cancellation).
  const double beta1 = 1e-3 * beta_low_;
  double k[3];
  for (int i = 0; i < 3; ++i) {
    const double beta = (i + 1) * beta1;
    double xb, zb;
    CentreAtNormalAngle(beta, &xb, &zb);
    k[i] = (x_max_ - xb) / (beta * beta);
  }
  fall_k0_ = 3 * k[0] - 3 * k[1] + k[2];
  fall_k1_ = (-5 * k[0] + 8 * k[1] - 3 * k[2]) / (2 * beta1);
  double z_unused;
  if (beta_low_ == beta_n) {
    // The contact at t = 0: the normal with n_y = 0, n·d = 0 is ∝ (tanθ, 0, −1), taken exactly
    // rather than through the rounded angle β_n (whose n_y ≈ 1e-17 would put x_low above
    // x_eq = 0 at θ = 0, so that At(x_eq) would be refused).
    CentreForNormal(B_, 0.0, -1.0, &x_low_, &z_unused);
  } else {
    CentreAtNormalAngle(beta_low_, &x_low_, &z_unused);
  }
}

void SpheroidOnRods::CentreForNormal(double nx, double ny, double nz, double* x, double* z) const {
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  const auto c = ContactForNormal(nx / len, ny / len, nz / len, a_, b_, B_, T_, r_);
  *x = c.x;
  *z = c.z;
}

void SpheroidOnRods::CentreAtNormalAngle(double beta, double* x, double* z) const {
  const auto c = ContactAtAngle(beta, a_, b_, B_, T_, r_);
  *x = c.x;
  *z = c.z;
}

double SpheroidOnRods::RestX(double mu) const {
  // z' = −n_x/n_z = −mu with n·d = 0: n ∝ (−mu, (B + mu)/T, −1).
  double x, z;
  CentreForNormal(-mu, (B_ + mu) / T_, -1.0, &x, &z);
  return x;
}

double SpheroidOnRods::FallOffBeta(double x) const {
  // x_max − x = k0·β² + k1·β³, by fixed-point iteration from β = sqrt((x_max − x)/k0); the
  // neglected k2·β⁴ is ≲ β² ≲ 1e-9 relative where this is used.
  const double d = x_max_ - x;  // exact near x_max (Sterbenz)
  double beta = std::sqrt(d / fall_k0_);
  for (int i = 0; i < 3; ++i) beta = std::sqrt(d / (fall_k0_ + fall_k1_ * beta));
  return beta;
}

double SpheroidOnRods::BetaOf(double x) const {
  if (x >= x_max_) return 0.0;
  using Jet = ceres::Jet<double, 1>;
  auto f = [&](double beta) {
    const auto c = ContactAtAngle(Jet(beta, 0), a_, b_, B_, T_, r_);
    return std::make_pair(c.x.a - x, c.x.v[0]);
  };
  // Start from the fall-off expansion and let Newton, kept inside the bracket, polish to full
  // precision.
  double guess = FallOffBeta(x);
  if (!(guess < beta_low_)) guess = 0.5 * beta_low_;
  std::uintmax_t iterations = 200;
  return boost::math::tools::newton_raphson_iterate(f, guess, 0.0, beta_low_,
                                                    std::numeric_limits<double>::digits - 2,
                                                    iterations);
}

SpheroidPathPoint<double> SpheroidOnRods::At(double x) const {
  // Within 1e-9·x_max of the fall-off x(β) = x_max − k·β² is flat: its rounding (ulps of x_max,
  // and its β = 0 value differs from the closed-form x_max by ulps) makes Newton's β noise of
  // relative size ulp(x_max)/(x_max − x), and the first-order carry below a step in β that is
  // not small (z'·(x − x(β)) with z' ~ 1e14 once gave z wrong by 18 % at the last double below
  // x_max). There β comes from the expansion about the closed-form x_max (x_max − x exact, to
  // ~1e-8 relative in β), and z, z' are those of β itself.
  const bool near_fall_off = x < x_max_ && x_max_ - x <= 1e-9 * x_max_;
  const auto c = ContactAtAngle(near_fall_off ? FallOffBeta(x) : BetaOf(x), a_, b_, B_, T_, r_);
  SpheroidPathPoint<double> p;
  p.dzdx = c.nz == 0.0 ? -std::numeric_limits<double>::infinity() : -c.nx / c.nz;
  // Elsewhere the solved β reproduces x to about an ulp; carry z to the requested x to first
  // order.
  p.z = std::isfinite(p.dzdx) && !near_fall_off ? c.z + p.dzdx * (x - c.x) : c.z;
  p.r_star = std::hypot(c.sx, c.sz);
  p.x_contact = x + c.sx;
  return p;
}

// ---- The path in the normal angle (appended for src/motion's equation of motion) -----------

SpheroidOnRods::NormalAnglePoint SpheroidOnRods::PathAtNormalAngle(double beta) const {
  // n(β) = cosβ·u + sinβ·v (unit, n·d = 0), n' = −sinβ·u + cosβ·v, n'' = −n.
  const double s1 = std::sqrt(1.0 + T_ * T_), dn = std::sqrt(1.0 + T_ * T_ + B_ * B_);
  const double u[3] = {-T_ / s1, 1.0 / s1, 0.0};
  const double v[3] = {B_ / (dn * s1), T_ * B_ / (dn * s1), -(1.0 + T_ * T_) / (dn * s1)};
  const double c = std::cos(beta), s = std::sin(beta);
  double n[3], n1[3];
  for (int k = 0; k < 3; ++k) {
    n[k] = c * u[k] + s * v[k];
    n1[k] = -s * u[k] + c * v[k];
  }
  const double D[3] = {a_ * a_, b_ * b_, a_ * a_};
  // N = |D^½ n|, N' = (n·D n')/N, N'' = (n'·D n' + n·D n'')/N − N'²/N with n·D n'' = −N².
  double nn = 0, nn1 = 0, n1n1 = 0;
  for (int k = 0; k < 3; ++k) {
    nn += D[k] * n[k] * n[k];
    nn1 += D[k] * n[k] * n1[k];
    n1n1 += D[k] * n1[k] * n1[k];
  }
  const double N = std::sqrt(nn), N1 = nn1 / N, N2 = (n1n1 - nn) / N - N1 * N1 / N;
  // S = D n/N (contact point from the centre); S', S''.
  double S[3], S1[3], S2[3];
  for (int k = 0; k < 3; ++k) {
    S[k] = D[k] * n[k] / N;
    S1[k] = D[k] * n1[k] / N - D[k] * n[k] * N1 / (N * N);
    S2[k] = -D[k] * n[k] / N - 2.0 * D[k] * n1[k] * N1 / (N * N) - D[k] * n[k] * N2 / (N * N) +
            2.0 * D[k] * n[k] * N1 * N1 / (N * N * N);
  }
  // t = (S_y + r n_y)/T, x = t − S_x − r n_x, z = t·B − S_z − r n_z (and the same for the
  // derivatives, with n'' = −n).
  auto centre = [&](const double* Sk, const double* nk, double* x, double* z) {
    const double t = (Sk[1] + r_ * nk[1]) / T_;
    *x = t - Sk[0] - r_ * nk[0];
    *z = t * B_ - Sk[2] - r_ * nk[2];
  };
  const double n2[3] = {-n[0], -n[1], -n[2]};
  NormalAnglePoint p;
  centre(S, n, &p.x, &p.z);
  centre(S1, n1, &p.dx, &p.dz);
  centre(S2, n2, &p.ddx, &p.ddz);
  p.r_star = std::hypot(S[0], S[2]);
  p.dr_star = (S[0] * S1[0] + S[2] * S1[2]) / p.r_star;
  return p;
}

double SpheroidOnRods::NormalAngleAtEquilibrium() const {
  // n ∝ (0, B/T, −1): β = atan2(n·v, n·u) with u, v of PathAtNormalAngle.
  const double s1 = std::sqrt(1.0 + T_ * T_), dn = std::sqrt(1.0 + T_ * T_ + B_ * B_);
  const double ny = B_ / T_, nz = -1.0;
  const double nu = ny / s1;
  const double nv = (T_ * B_ * ny / dn - (1.0 + T_ * T_) * nz / dn) / s1;
  return std::atan2(nv, nu);
}

}  // namespace uphill
