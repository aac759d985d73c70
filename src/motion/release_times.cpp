// ReleaseTimes (motion.hpp): a whole release trajectory t(x_1 … x_n) of a sphere or spheroid on
// line rails by fixed Gauss–Legendre rules on arrays of nodes.
//
// Integrand (docs/physics.md "Energy"; the substitution of the quadrature method written in
// v = sinh(w/2)): with u = ψ − ψ0 the ellipse parameter measured from X, u0 its release value,
//   u = u0·(1 + 2v²),  a2 = (u − u0)/2 = u0·v²,  a1 = (u + u0)/2 = u0 + a2,
//   dt/dv = 2·sqrt(K·M·a1·a2 / (g·z_eq·sin a1·sin a2·(1 + v²))),
//   M = x_max²·cos²ψ + z_eq²·sin²u,  K = 1 + I/d,  d = cos²(ψ+γ) + q·sin²(ψ+γ).
// v is the cosh substitution of motion.hpp without its exp: a position maps to
// v = sqrt((u − u0)/(2·u0)) and a node needs one sin (of a2); cos a2 = sqrt(1 − sin²a2)
// (a2 < π/4), and ψ = ψ_rel + 2·a2, u = u0 + 2·a2 by angle sums with the release's sin/cos
// precomputed. The drop z(u0) − z(u) = 2·z_eq·sin a1·sin a2 is a product of two accurate
// factors (cos u0 − cos u would lose all digits at the first nodes). No allocation, no
// std::function: the nodes of a block of intervals are arrays; with AVX2 + FMA (run-time check)
// four nodes at a time on glibc's libmvec (sin; atan for the positions), as
// src/model/batch_convert.cpp does, otherwise the same expressions in scalar libm.
//
// Node count, a priori: dt/dv is analytic except at a few complex points: v = ±i (the mirror
// release point u = −u0) and the images of the zeros of K (d = −I) and of sin a1, sin a2, in
// closed form (the zeros of M are those of d and cancel the poles of K in K·M). For an
// interval of length h whose midpoint is at distance ℓ from the nearest of them, the
// Gauss–Legendre error of N nodes is ≲ C·ρ^(−2N) relative, ρ = ξ + sqrt(ξ² − 1), ξ = 2ℓ/h
// (the Bernstein ellipse through the worst-placed point at that distance); C = 1 covers the
// measured constants (≤ 0.7 over release points from 1 + 1e-6 to 3 X, θ 0.01° … 10°). Each
// interval gets the smallest N ≤ 12 meeting the tolerance (intervals are grouped by N in
// blocks so that the node arrays stay regular); one needing more is split into 2^k panels.

#include <algorithm>
#include <array>
#include <boost/math/quadrature/gauss.hpp>
#include <cmath>
#include <complex>
#include <numbers>

#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "model/libmvec_avx2.hpp"
#include "internal/motion_engine.hpp"
#include "model/number_text.hpp"

#define UPHILL_RELEASE_AVX2 UPHILL_LIBMVEC_AVX2

namespace uphill {
namespace {

using internal::EllipseCoordinate;

constexpr int kMinNodes = 2, kMaxNodes = 12;
constexpr std::size_t kBlock = 64;  // panels per block (arrays of 512 B: they stay in L1)

// Per-trajectory constants of the integrand and of the position map.
struct Release {
  double u0;                    // release u (> 0)
  double sin_u0, cos_u0;
  double sin_rel, cos_rel;      // sin/cos of ψ at the release (x0/x_max, …)
  double cg, sg, q, inertia;    // cos/sin γ, q = A²/P, I/(m a²)
  double xm2, ze2, four_inv_gz; // x_max², z_eq², 4/(g·z_eq)
  double x0, x_max, inv_xm;
  double inv_2u0;
};

// ---- scalar kernels --------------------------------------------------------------------------

inline double IntegrandAt(const Release& r, double v) {
  const double v2 = v * v;
  const double a2 = r.u0 * v2, a1 = r.u0 + a2;
  const double s = std::sin(a2), c = std::sqrt(1.0 - s * s);
  const double sin_a1 = r.sin_u0 * c + r.cos_u0 * s;
  const double s2 = 2.0 * s * c, c2 = 1.0 - 2.0 * s * s;  // sin, cos of u − u0 = 2·a2
  const double su = r.sin_u0 * c2 + r.cos_u0 * s2;
  const double sp = r.sin_rel * c2 + r.cos_rel * s2, cp = r.cos_rel * c2 - r.sin_rel * s2;
  const double cw = cp * r.cg - sp * r.sg, sw = sp * r.cg + cp * r.sg;
  const double d = cw * cw + r.q * sw * sw;
  const double metric = r.xm2 * cp * cp + r.ze2 * su * su;
  // a2/sin a2 → 1 where a2 = 0 (v = 0, never a Gauss node; kept finite anyway).
  const double num_a2 = s == 0.0 ? 1.0 : a2, den_s = s == 0.0 ? 1.0 : s;
  return std::sqrt((d + r.inertia) * metric * a1 * num_a2 / (d * sin_a1 * den_s * (1.0 + v2)) * r.four_inv_gz);
}

// acc[j] += omega·f(c[j] + hh[j]·xi), j < n.
void AccumulateScalar(const Release& r, const double* c, const double* hh, double xi, double omega,
                      double* acc, std::size_t n) {
  for (std::size_t j = 0; j < n; ++j) acc[j] += omega * IntegrandAt(r, c[j] + hh[j] * xi);
}

// v of position x (x0 < x ≤ x_max): u − u0 = ψ − ψ_rel = atan(sin/cos of the difference),
// sin(ψ − ψ_rel) = (x − x0)(x + x0)/x_max² / (sinψ·cosψ_rel + cosψ·sinψ_rel) (no cancellation
// near x0; the difference is below π/2, so its cosine is > 0).
inline double VOfX(const Release& r, double x) {
  const double sp = x * r.inv_xm;
  const double cp = std::sqrt(std::max(0.0, (r.x_max - x) * r.inv_xm * (1.0 + sp)));
  const double den = sp * r.cos_rel + cp * r.sin_rel;
  const double sin_du = (x - r.x0) * (x + r.x0) * r.inv_xm * r.inv_xm;
  const double cos_du = cp * r.cos_rel + sp * r.sin_rel;
  return std::sqrt(std::atan(sin_du / (den * cos_du)) * r.inv_2u0);
}

void PositionsScalar(const Release& r, const double* x, double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) v[i] = VOfX(r, x[i]);
}

// ---- AVX2 + FMA kernels (only reached after the run-time check; see batch_convert.cpp) ----
#if UPHILL_RELEASE_AVX2
#pragma GCC push_options
#pragma GCC target("avx2,fma")

inline __m256d Set(double v) { return _mm256_set1_pd(v); }

// As AccumulateScalar; n a multiple of 4 (the block arrays are padded with harmless values),
// n ≤ kScratch. Two passes: the libmvec calls first, then the arithmetic with no call inside,
// so that the out-of-order core overlaps the long sqrt/div chains of successive iterations.
constexpr std::size_t kScratch = 128;
void AccumulateAvx2(const Release& r, const double* c, const double* hh, double xi, double omega,
                    double* acc, std::size_t n) {
  alignas(32) double v_[kScratch], s_[kScratch];
  const __m256d one = Set(1.0), two = Set(2.0), zero = _mm256_setzero_pd();
  const __m256d u0 = Set(r.u0), sin_u0 = Set(r.sin_u0), cos_u0 = Set(r.cos_u0);
  const __m256d sin_rel = Set(r.sin_rel), cos_rel = Set(r.cos_rel), cg = Set(r.cg), sg = Set(r.sg);
  const __m256d q = Set(r.q), inertia = Set(r.inertia), xm2 = Set(r.xm2), ze2 = Set(r.ze2);
  const __m256d scale = Set(r.four_inv_gz), vxi = Set(xi), vom = Set(omega);
  for (std::size_t j = 0; j < n; j += 4) {
    const __m256d v = _mm256_fmadd_pd(_mm256_loadu_pd(hh + j), vxi, _mm256_loadu_pd(c + j));
    _mm256_store_pd(v_ + j, v);
    _mm256_store_pd(s_ + j, _ZGVdN4v_sin(_mm256_mul_pd(u0, _mm256_mul_pd(v, v))));
  }
  for (std::size_t j = 0; j < n; j += 4) {
    const __m256d v = _mm256_load_pd(v_ + j), s = _mm256_load_pd(s_ + j);
    const __m256d v2 = _mm256_mul_pd(v, v);
    const __m256d a2 = _mm256_mul_pd(u0, v2), a1 = _mm256_add_pd(u0, a2);
    const __m256d cs = _mm256_sqrt_pd(_mm256_fnmadd_pd(s, s, one));
    const __m256d sin_a1 = _mm256_fmadd_pd(sin_u0, cs, _mm256_mul_pd(cos_u0, s));
    const __m256d s2 = _mm256_mul_pd(two, _mm256_mul_pd(s, cs));
    const __m256d c2 = _mm256_fnmadd_pd(_mm256_mul_pd(two, s), s, one);
    const __m256d su = _mm256_fmadd_pd(sin_u0, c2, _mm256_mul_pd(cos_u0, s2));
    const __m256d sp = _mm256_fmadd_pd(sin_rel, c2, _mm256_mul_pd(cos_rel, s2));
    const __m256d cp = _mm256_fmsub_pd(cos_rel, c2, _mm256_mul_pd(sin_rel, s2));
    const __m256d cw = _mm256_fmsub_pd(cp, cg, _mm256_mul_pd(sp, sg));
    const __m256d sw = _mm256_fmadd_pd(sp, cg, _mm256_mul_pd(cp, sg));
    const __m256d d = _mm256_fmadd_pd(cw, cw, _mm256_mul_pd(q, _mm256_mul_pd(sw, sw)));
    const __m256d metric = _mm256_fmadd_pd(_mm256_mul_pd(xm2, cp), cp, _mm256_mul_pd(_mm256_mul_pd(ze2, su), su));
    const __m256d at_zero = _mm256_cmp_pd(s, zero, _CMP_EQ_OQ);
    const __m256d num_a2 = _mm256_blendv_pd(a2, one, at_zero), den_s = _mm256_blendv_pd(s, one, at_zero);
    const __m256d num = _mm256_mul_pd(_mm256_mul_pd(_mm256_add_pd(d, inertia), metric), _mm256_mul_pd(a1, num_a2));
    const __m256d den = _mm256_mul_pd(_mm256_mul_pd(d, sin_a1), _mm256_mul_pd(den_s, _mm256_add_pd(one, v2)));
    const __m256d f = _mm256_sqrt_pd(_mm256_mul_pd(_mm256_div_pd(num, den), scale));
    _mm256_storeu_pd(acc + j, _mm256_fmadd_pd(vom, f, _mm256_loadu_pd(acc + j)));
  }
}

void PositionsAvx2(const Release& r, const double* x, double* v, std::size_t n) {
  std::size_t i = 0;
  const __m256d inv_xm = Set(r.inv_xm), one = Set(1.0), zero = _mm256_setzero_pd();
  const __m256d x_max = Set(r.x_max), x0 = Set(r.x0), sin_rel = Set(r.sin_rel), cos_rel = Set(r.cos_rel);
  const __m256d inv_xm2 = Set(r.inv_xm * r.inv_xm), inv_2u0 = Set(r.inv_2u0);
  for (; i + 4 <= n; i += 4) {
    const __m256d vx = _mm256_loadu_pd(x + i);
    const __m256d sp = _mm256_mul_pd(vx, inv_xm);
    const __m256d om = _mm256_max_pd(zero, _mm256_mul_pd(_mm256_sub_pd(x_max, vx), inv_xm));
    const __m256d cp = _mm256_sqrt_pd(_mm256_mul_pd(om, _mm256_add_pd(one, sp)));
    const __m256d den = _mm256_fmadd_pd(sp, cos_rel, _mm256_mul_pd(cp, sin_rel));
    const __m256d sin_du = _mm256_mul_pd(_mm256_mul_pd(_mm256_sub_pd(vx, x0), _mm256_add_pd(vx, x0)), inv_xm2);
    const __m256d cos_du = _mm256_fmadd_pd(cp, cos_rel, _mm256_mul_pd(sp, sin_rel));
    const __m256d du = _ZGVdN4v_atan(_mm256_div_pd(sin_du, _mm256_mul_pd(den, cos_du)));
    _mm256_storeu_pd(v + i, _mm256_sqrt_pd(_mm256_mul_pd(du, inv_2u0)));
  }
  PositionsScalar(r, x + i, v + i, n - i);
}

#pragma GCC pop_options
#endif  // UPHILL_RELEASE_AVX2

// ---- Gauss–Legendre rules (Boost.Math), expanded to all N nodes ------------------------------

struct Rule {
  int n = 0;
  std::array<double, kMaxNodes> xi{}, omega{};
};

template <unsigned N>
Rule MakeRule() {
  using G = boost::math::quadrature::gauss<double, N>;
  const auto& x = G::abscissa();
  const auto& wt = G::weights();
  Rule rule;
  rule.n = N;
  int k = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    rule.xi[k] = x[i];
    rule.omega[k++] = wt[i];
    if (x[i] != 0.0) {
      rule.xi[k] = -x[i];
      rule.omega[k++] = wt[i];
    }
  }
  return rule;
}

const Rule& RuleOf(int n) {
  static const std::array<Rule, kMaxNodes + 1> rules = [] {
    std::array<Rule, kMaxNodes + 1> r{};
    r[2] = MakeRule<2>();
    r[3] = MakeRule<3>();
    r[4] = MakeRule<4>();
    r[5] = MakeRule<5>();
    r[6] = MakeRule<6>();
    r[7] = MakeRule<7>();
    r[8] = MakeRule<8>();
    r[9] = MakeRule<9>();
    r[10] = MakeRule<10>();
    r[11] = MakeRule<11>();
    r[12] = MakeRule<12>();
    return r;
  }();
  return rules[n];
}

// ---- a-priori node count ---------------------------------------------------------------------

// Singularities of dt/dv in the v plane as (|Re v|, (Im v)²) (dt/dv is even in v and real on
// the real axis: ±v_s and their conjugates), the dominated ones removed.
constexpr int kMaxSingularities = 8;
struct Singularities {
  std::array<double, kMaxSingularities> re{}, im2{};
  int n = 0;
};

Singularities FindSingularities(const EllipseCoordinate& e, const Release& r, double v_end) {
  using C = std::complex<double>;
  static_assert(kMaxSingularities >= 8);
  const double pi = std::numbers::pi;
  const double psi0 = std::atan2(e.sin_psi0(), e.cos_psi0());
  const double gamma = std::atan2(r.sg, r.cg);
  std::array<C, kMaxSingularities> u{};
  int n = 0;
  // K = 0 (d = −I): ψ + γ = π/2 + kπ ± i·atanh(sqrt((q + I)/(1 + I))). The poles of K (d = 0)
  // are no singularities of K·M: M = R*²·(dφ/dψ)² (φ the rotation angle, rolling) = a²·d·(dφ/dψ)²
  // vanishes there too (tests/motion_property_test.cpp checks the estimate this gives).
  const double y_zero = std::atanh(std::sqrt((r.q + r.inertia) / (1.0 + r.inertia)));
  for (int k = -1; k <= 1; ++k) u[n++] = C(pi / 2 + k * pi - gamma - psi0, y_zero);
  // sin a1 = 0 or sin a2 = 0 away from a = 0: u = ±2π ± u0; and v = ±i (u = −u0).
  for (double sgn : {-1.0, 1.0})
    for (double t : {-1.0, 1.0}) u[n++] = C(sgn * 2 * pi + t * r.u0, 0.0);
  u[n++] = C(-r.u0, 0.0);
  std::array<double, kMaxSingularities> re{}, im2{};
  for (int k = 0; k < n; ++k) {
    const C v = std::sqrt((u[k] - r.u0) * r.inv_2u0);  // v² = (u − u0)/(2·u0)
    re[k] = std::abs(v.real());
    im2[k] = v.imag() * v.imag();
  }
  // Drop s when another is at least as near at both ends of [0, v_end] (squared distances to a
  // midpoint c differ by a linear function of c).
  auto dist2 = [&](int k, double c) { return (c - re[k]) * (c - re[k]) + im2[k]; };
  Singularities out;
  for (int k = 0; k < n; ++k) {
    bool dominated = false;
    for (int m = 0; m < n && !dominated; ++m) {
      if (m == k) continue;
      const bool le = dist2(m, 0.0) <= dist2(k, 0.0) && dist2(m, v_end) <= dist2(k, v_end);
      const bool lt = dist2(m, 0.0) < dist2(k, 0.0) || dist2(m, v_end) < dist2(k, v_end);
      dominated = le && (lt || m < k);
    }
    if (dominated) continue;
    out.re[out.n] = re[k];
    out.im2[out.n++] = im2[k];
  }
  return out;
}

// (h/(2ℓ))² thresholds: N nodes suffice on a panel while h²/(4ℓ²) ≤ limit[N].
struct NodeLimits {
  std::array<double, kMaxNodes + 1> limit{};
  double tolerance;
  explicit NodeLimits(double tol) : tolerance(tol) {
    constexpr double kC = 1.0;  // see the top of the file
    for (int n = kMinNodes; n <= kMaxNodes; ++n) {
      const double rho = std::pow(kC / tolerance, 1.0 / (2 * n));
      const double xi = 0.5 * (rho + 1.0 / rho);  // ρ = ξ + sqrt(ξ² − 1)
      limit[n] = 1.0 / (xi * xi);
    }
  }
  // The smallest N with need ≤ limit[N] (limit grows with N), capped at kMaxNodes.
  int Nodes(double need) const {
    int n = kMinNodes;
    for (int k = kMinNodes; k < kMaxNodes; ++k) n += need > limit[k];
    return n;
  }
};

inline double Need(const Singularities& s, double c, double h) {
  double l2 = 1e300;
  for (int k = 0; k < s.n; ++k) l2 = std::min(l2, (c - s.re[k]) * (c - s.re[k]) + s.im2[k]);
  return h * h / (4.0 * l2);
}

Release MakeRelease(const EllipseCoordinate& e, double x0, double g) {
  Release r{};
  r.u0 = e.UOfX(x0);
  r.sin_u0 = std::sin(r.u0);
  r.cos_u0 = std::cos(r.u0);
  r.x0 = x0;
  r.x_max = e.x_max();
  r.inv_xm = 1.0 / e.x_max();
  r.sin_rel = x0 * r.inv_xm;
  r.cos_rel = std::sqrt(std::max(0.0, (e.x_max() - x0) * r.inv_xm * (1.0 + r.sin_rel)));
  r.cg = e.cos_gamma();
  r.sg = e.sin_gamma();
  r.q = e.q();
  r.inertia = e.inertia();
  r.xm2 = e.x_max() * e.x_max();
  r.ze2 = e.z_eq() * e.z_eq();
  r.four_inv_gz = 4.0 / (g * e.z_eq());
  r.inv_2u0 = 0.5 / r.u0;
  return r;
}

// Integrals of up to kBlock panels (midpoints c, half-widths hh, node counts nodes) into out:
// grouped by node count, each group gathered into arrays padded to a multiple of 4 (copies of a
// real panel) for the AVX2 kernel.
void EvaluatePanels(const Release& r, bool avx2, const double* c, const double* hh, const int* nodes,
                    std::size_t count, double* out) {
  alignas(32) double gc[kBlock + 4], ghh[kBlock + 4], acc[kBlock + 4];
  unsigned char index[kBlock];
  unsigned present = 0;  // bit n set: some panel has n nodes
  for (std::size_t j = 0; j < count; ++j) present |= 1u << nodes[j];
  for (int n = kMinNodes; n <= kMaxNodes; ++n) {
    if (!(present >> n & 1u)) continue;
    std::size_t m = 0;
    for (std::size_t j = 0; j < count; ++j) {
      if (nodes[j] != n) continue;
      gc[m] = c[j];
      ghh[m] = hh[j];
      index[m++] = static_cast<unsigned char>(j);
    }
    const std::size_t padded = (m + 3) & ~std::size_t{3};
    for (std::size_t k = m; k < padded; ++k) {
      gc[k] = gc[0];
      ghh[k] = ghh[0];
    }
    std::fill(acc, acc + padded, 0.0);
    const Rule& rule = RuleOf(n);
    for (int k = 0; k < n; ++k) {
#if UPHILL_RELEASE_AVX2
      if (avx2) {
        AccumulateAvx2(r, gc, ghh, rule.xi[k], rule.omega[k], acc, padded);
        continue;
      }
#endif
      AccumulateScalar(r, gc, ghh, rule.xi[k], rule.omega[k], acc, m);
    }
    for (std::size_t k = 0; k < m; ++k) out[index[k]] = ghh[k] * acc[k];
  }
}

}  // namespace

void ReleaseTimes(const Scene& scene, double x0, std::span<const double> xs, std::span<double> t,
                  const ReleaseTimesOptions& o) {
  using namespace internal;
  if (!IsEllipse(scene)) throw InputError("scene", "ReleaseTimes needs a sphere or spheroid on line rails");
  if (!(x0 > *scene.x_eq() && x0 < scene.x_max()))
    throw InputError("x0", "must lie in (X, x_max) = (" + ExactText(*scene.x_eq()) + ", " + ExactText(scene.x_max()) +
                               ") m (got " + ExactText(x0) + " m)");
  RequireGravity("g", o.g);
  if (o.nodes != 0 && (o.nodes < kMinNodes || o.nodes > kMaxNodes))
    throw InputError("nodes", "must be 0 (chosen from the tolerance) or 2 ... 12 (got " + std::to_string(o.nodes) + ")");
  if (!(o.tolerance >= 1e-15 && o.tolerance <= 1e-2))
    throw InputError("tolerance", "must lie in [1e-15, 1e-2] (got " + ExactText(o.tolerance) + ")");
  if (t.size() != xs.size()) throw InputError("t", "must have as many elements as xs");
  const double x_max = scene.x_max();
  double prev = x0;
  for (double x : xs) {
    if (!(x > prev && x <= x_max))
      throw InputError("xs", "must increase strictly within (x0, x_max] (got " + ExactText(x) + " m after " + ExactText(prev) + " m)");
    prev = x;
  }
  if (xs.empty()) return;
  bool avx2 = UseAvx2(o.kernel);

  const EllipseCoordinate e = MakeEllipse(scene);
  const Release r = MakeRelease(e, x0, o.g);
  // Positions → v, written into t (each t[i] is read before the block that overwrites it with
  // the interval's integral; a prefix sum then makes the times).
#if UPHILL_RELEASE_AVX2
  if (avx2) PositionsAvx2(r, xs.data(), t.data(), xs.size());
  else PositionsScalar(r, xs.data(), t.data(), xs.size());
#else
  (void)avx2;
  PositionsScalar(r, xs.data(), t.data(), xs.size());
#endif
  // x = x_max exactly: v of u_max, as Motion's end.
  if (xs.back() == x_max) t.back() = std::sqrt((e.u_max() - r.u0) * r.inv_2u0);

  const Singularities sing = o.nodes ? Singularities{} : FindSingularities(e, r, t.back());
  // The limits depend on the tolerance only: kept from the previous call when it is the same
  // (copied to a local so that the loops below see plain values).
  thread_local NodeLimits cached(1e-13);
  if (cached.tolerance != o.tolerance) cached = NodeLimits(o.tolerance);
  const NodeLimits limits = cached;
  const double max_need = limits.limit[kMaxNodes];

  // Intervals in chunks of up to kBlock; t[i] still holds v_i when interval i is read and gets
  // its integral when its chunk is evaluated. An interval needing more than kMaxNodes nodes is
  // split into 2^k equal panels, evaluated on their own.
  double c[kBlock], hh[kBlock], piece[kBlock];
  int nodes[kBlock];
  std::size_t first = 0, fill = 0;
  auto flush = [&] {
    EvaluatePanels(r, avx2, c, hh, nodes, fill, piece);
    std::copy(piece, piece + fill, t.begin() + first);
    fill = 0;
  };
  double v_prev = 0.0;
  for (std::size_t i0 = 0; i0 < xs.size(); i0 += kBlock) {
    // Needs and node counts of the chunk's intervals, in loops the compiler vectorises.
    const std::size_t m = std::min(kBlock, xs.size() - i0);
    double lo[kBlock], need[kBlock];
    int count[kBlock];
    lo[0] = v_prev;
    for (std::size_t j = 1; j < m; ++j) lo[j] = t[i0 + j - 1];
    for (std::size_t j = 0; j < m; ++j) {
      const double hi = t[i0 + j];
      c[j] = 0.5 * (lo[j] + hi);
      hh[j] = 0.5 * (hi - lo[j]);
      need[j] = 1e300;
    }
    v_prev = t[i0 + m - 1];
    if (o.nodes) {
      std::fill(need, need + m, 0.0);
      std::fill(count, count + m, o.nodes);
    } else {
      for (int k = 0; k < sing.n; ++k) {
        const double re = sing.re[k], im2 = sing.im2[k];
        for (std::size_t j = 0; j < m; ++j) need[j] = std::min(need[j], (c[j] - re) * (c[j] - re) + im2);
      }
      for (std::size_t j = 0; j < m; ++j) {
        need[j] = hh[j] * hh[j] / need[j];  // h²/(4ℓ²)
        count[j] = kMinNodes;
      }
      for (int k = kMinNodes; k < kMaxNodes; ++k)
        for (std::size_t j = 0; j < m; ++j) count[j] += need[j] > limits.limit[k];
    }
    // Panels: the intervals themselves, except those needing more than kMaxNodes nodes, which
    // are split into 2^k equal panels and evaluated on their own.
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t i = i0 + j;
      if (need[j] <= max_need) {
        if (fill == 0) first = i;
        c[fill] = c[j];
        hh[fill] = hh[j];
        nodes[fill++] = count[j];
        continue;
      }
      if (fill) flush();
      const double a0 = c[j] - hh[j], b0 = c[j] + hh[j];
      int pieces = 2;
      for (; pieces < (1 << 20); pieces *= 2) {
        const double h = (b0 - a0) / pieces;
        bool ok = true;
        for (int p = 0; p < pieces && ok; ++p) ok = Need(sing, a0 + (p + 0.5) * h, h) <= max_need;
        if (ok) break;
      }
      const double h = (b0 - a0) / pieces;
      double sum = 0.0;
      double pc[kBlock], ph[kBlock];
      int pn[kBlock];
      std::size_t pf = 0;
      for (int p = 0; p < pieces; ++p) {
        const double a = a0 + p * h, b = p + 1 == pieces ? b0 : a + h;
        pc[pf] = 0.5 * (a + b);
        ph[pf] = 0.5 * (b - a);
        pn[pf] = limits.Nodes(Need(sing, pc[pf], b - a));
        if (++pf == kBlock || p + 1 == pieces) {
          EvaluatePanels(r, avx2, pc, ph, pn, pf, piece);
          for (std::size_t q = 0; q < pf; ++q) sum += piece[q];
          pf = 0;
        }
      }
      t[i] = sum;
    }
    if (fill) flush();
  }
  for (std::size_t i = 1; i < t.size(); ++i) t[i] += t[i - 1];
}

std::vector<double> ReleaseTimes(const Scene& scene, double x0, const std::vector<double>& xs,
                                 const ReleaseTimesOptions& options) {
  std::vector<double> t(xs.size());
  ReleaseTimes(scene, x0, xs, t, options);
  return t;
}

}  // namespace uphill
