#include "model/batch_convert.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "model/libmvec_avx2.hpp"
#include "internal/batch_kernels_avx2.hpp"
#include "internal/spheroid_on_rods_closed_forms.hpp"

#define UPHILL_BATCH_AVX2 UPHILL_LIBMVEC_AVX2

namespace uphill {
namespace {

// ---------------------------------------------------------------------------------------------
// Scalar kernels: the model's own expressions (rails.cpp, SpheroidOnLineRails, the rods closed
// forms, DoubleConeOnLineRails), so that kScalar is bit-identical to the scalar model.

void ScalarRailsTail(std::size_t i, const double* B, const double* T, const RailsArrays& out) {
  if (out.phi) out.phi[i] = std::atan2(T[i], std::hypot(1.0, B[i]));
}

void ScalarRailsFromApparatus(std::size_t n, const double* L, const double* H, const double* D,
                              LConvention convention, const RailsArrays& out, double* B,
                              double* T) {
  for (std::size_t i = 0; i < n; ++i) {
    const double horizontal = HorizontalDistance(L[i], H[i], D[i], convention);
    B[i] = H[i] / horizontal;
    T[i] = D[i] / (2 * horizontal);
    if (out.theta) out.theta[i] = std::atan2(H[i], horizontal);
    if (out.alpha) out.alpha[i] = 2 * std::atan2(D[i] / 2, horizontal);
    ScalarRailsTail(i, B, T, out);
  }
}

void ScalarRailsFromAngles(std::size_t n, const double* theta, const double* alpha,
                           const RailsArrays& out, double* B, double* T) {
  for (std::size_t i = 0; i < n; ++i) {
    B[i] = std::tan(theta[i]);
    T[i] = std::tan(alpha[i] / 2);
    if (out.theta) out.theta[i] = theta[i];
    if (out.alpha) out.alpha[i] = alpha[i];
    ScalarRailsTail(i, B, T, out);
  }
}

void ScalarSpheroid(std::size_t n, const double* a, const double* b, const double* r,
                    const double* B, const double* T, double* x_eq, double* x_max) {
  for (std::size_t i = 0; i < n; ++i) {
    if (r) {
      if (x_eq) x_eq[i] = SpheroidOnRodsXEq(a[i], b[i], B[i], T[i], r[i]);
      if (x_max) x_max[i] = SpheroidOnRodsXMax(a[i], b[i], T[i], r[i]);
    } else {
      const double A = a[i] * T[i] / b[i];
      if (x_eq) x_eq[i] = a[i] * B[i] / (A * std::hypot(A, B[i]));
      if (x_max) x_max[i] = std::hypot(a[i], b[i] / T[i]);
    }
  }
}

void ScalarDoubleCone(std::size_t n, const double* R, const double* h, const double* B,
                      const double* T, double* x_fall, double* theta0, double* q) {
  for (std::size_t i = 0; i < n; ++i) {
    const double kT = R[i] / h[i] * T[i];
    if (x_fall) x_fall[i] = h[i] / T[i];
    if (theta0) theta0[i] = std::atan(kT);
    if (q) q[i] = 1.0 + B[i] * B[i] - kT * kT;
  }
}

// ---------------------------------------------------------------------------------------------
// AVX2 + FMA kernels. Compiled for that target by pragma rather than by a per-file -mavx2: with
// -mavx2 on a whole file every inline function instantiated there (std::vector, <cmath> wrappers)
// may be emitted with AVX2 instructions and chosen by the linker for the whole program, which then
// crashes on a CPU without AVX2. Here only the functions defined between push and pop are AVX2
// code, and they are reached only after the run-time check.
#if UPHILL_BATCH_AVX2
#pragma GCC push_options
#pragma GCC target("avx2,fma")

using internal::avx2::Hypot;  // the shared expressions: internal/batch_kernels_avx2.hpp

// Loads n < 4 values padded with `pad` (a harmless in-domain value), so that a short tail goes
// through the same vector code as full lanes: every element's result depends on its inputs only.
inline __m256d LoadTail(const double* p, std::size_t n, double pad) {
  alignas(32) double tmp[4] = {pad, pad, pad, pad};
  for (std::size_t k = 0; k < n; ++k) tmp[k] = p[k];
  return _mm256_load_pd(tmp);
}
inline void StoreTail(double* p, std::size_t n, __m256d v) {
  alignas(32) double tmp[4];
  _mm256_store_pd(tmp, v);
  for (std::size_t k = 0; k < n; ++k) p[k] = tmp[k];
}

// Loads lanes [i, i + 4) or the padded tail; m = number of valid lanes.
inline __m256d Load(const double* p, std::size_t i, std::size_t m, double pad) {
  return m == 4 ? _mm256_loadu_pd(p + i) : LoadTail(p + i, m, pad);
}
inline void Store(double* p, std::size_t i, std::size_t m, __m256d v) {
  if (!p) return;
  if (m == 4) {
    _mm256_storeu_pd(p + i, v);
  } else {
    StoreTail(p + i, m, v);
  }
}

inline void Avx2RailsTail(std::size_t i, std::size_t m, __m256d B, __m256d T,
                          const RailsArrays& out, double* B_out, double* T_out) {
  Store(B_out, i, m, B);
  Store(T_out, i, m, T);
  if (out.phi) Store(out.phi, i, m, _ZGVdN4v_atan(internal::avx2::PhiArgument(B, T)));
}

void Avx2RailsFromApparatus(std::size_t n, const double* L, const double* H, const double* D,
                            LConvention convention, const RailsArrays& out, double* B_out,
                            double* T_out) {
  const __m256d half = _mm256_set1_pd(0.5), two = _mm256_set1_pd(2.0);
  for (std::size_t i = 0; i < n; i += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - i);
    const __m256d l = Load(L, i, m, 1.0), h = Load(H, i, m, 0.0), d = Load(D, i, m, 0.1);
    __m256d horizontal = l;
    if (convention == LConvention::kAlongRail) {
      const __m256d s = Hypot(h, _mm256_mul_pd(d, half));  // D/2 is exact
      horizontal = _mm256_sqrt_pd(_mm256_mul_pd(_mm256_sub_pd(l, s), _mm256_add_pd(l, s)));
    }
    const __m256d B = internal::avx2::TanTheta(h, horizontal);
    const __m256d T = internal::avx2::TanHalfAlpha(d, horizontal);
    // atan(H/Lh) = atan2(H, Lh) for H ≥ 0, Lh > 0; B is the ratio the model uses anyway, and
    // atan is ~1.4× cheaper than atan2 in libmvec.
    if (out.theta) Store(out.theta, i, m, _ZGVdN4v_atan(B));
    if (out.alpha) Store(out.alpha, i, m, _mm256_mul_pd(two, _ZGVdN4v_atan(T)));
    Avx2RailsTail(i, m, B, T, out, B_out, T_out);
  }
}

void Avx2RailsFromAngles(std::size_t n, const double* theta, const double* alpha,
                         const RailsArrays& out, double* B_out, double* T_out) {
  const __m256d half = _mm256_set1_pd(0.5);
  for (std::size_t i = 0; i < n; i += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - i);
    const __m256d th = Load(theta, i, m, 0.1), al = Load(alpha, i, m, 0.1);
    const __m256d B = _ZGVdN4v_tan(th);
    const __m256d T = _ZGVdN4v_tan(_mm256_mul_pd(al, half));
    Store(out.theta, i, m, th);
    Store(out.alpha, i, m, al);
    Avx2RailsTail(i, m, B, T, out, B_out, T_out);
  }
}

void Avx2Spheroid(std::size_t n, const double* a, const double* b, const double* r,
                  const double* tB, const double* tT, double* x_eq, double* x_max) {
  const __m256d one = _mm256_set1_pd(1.0);
  for (std::size_t i = 0; i < n; i += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - i);
    const __m256d va = Load(a, i, m, 1.0), vb = Load(b, i, m, 1.0);
    const __m256d B = Load(tB, i, m, 0.1), T = Load(tT, i, m, 0.1);
    if (r) {
      const __m256d vr = Load(r, i, m, 0.0);
      if (x_eq) {
        const __m256d bB = _mm256_mul_pd(vb, B);
        const __m256d lhs = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(vb, vb), B),
                                          _mm256_mul_pd(T, Hypot(bB, _mm256_mul_pd(va, T))));
        const __m256d rhs =
            _mm256_div_pd(_mm256_mul_pd(vr, B), _mm256_mul_pd(T, Hypot(B, T)));
        Store(x_eq, i, m, _mm256_add_pd(lhs, rhs));
      }
      if (x_max) {
        const __m256d csc = _mm256_div_pd(_mm256_sqrt_pd(_mm256_fmadd_pd(T, T, one)), T);
        Store(x_max, i, m, _mm256_fmadd_pd(vr, csc, Hypot(va, _mm256_div_pd(vb, T))));
      }
    } else {
      if (x_eq) Store(x_eq, i, m, internal::avx2::SpheroidXEq(va, vb, B, T));
      if (x_max) Store(x_max, i, m, internal::avx2::SpheroidXMax(va, vb, T));
    }
  }
}

void Avx2DoubleCone(std::size_t n, const double* R, const double* h, const double* tB,
                    const double* tT, double* x_fall, double* theta0, double* q) {
  const __m256d one = _mm256_set1_pd(1.0);
  for (std::size_t i = 0; i < n; i += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - i);
    const __m256d vR = Load(R, i, m, 1.0), vh = Load(h, i, m, 1.0);
    const __m256d B = Load(tB, i, m, 0.1), T = Load(tT, i, m, 0.1);
    const __m256d kT = _mm256_mul_pd(_mm256_div_pd(vR, vh), T);
    Store(x_fall, i, m, _mm256_div_pd(vh, T));
    if (theta0) Store(theta0, i, m, _ZGVdN4v_atan(kT));
    // 1 + B² − (kT)²: the difference of squares as (1 + B²) − kT·kT with one rounding.
    Store(q, i, m, _mm256_fnmadd_pd(kT, kT, _mm256_fmadd_pd(B, B, one)));
  }
}

// The converter's common case in one pass, with the algebra arranged for the fewest divisions
// (the divider, not the atan, limits a naive translation): with inv = 1/L,
//   B = H·inv, T = D·inv/2, θ = atan(B), α = 2·atan(T),
//   X = a·B/(A·hypot(A, B)) = 2b·H·L/(D·sqrt(c²D² + H²)),  c = a/(2b)   (A = a·T/b; L cancels)
// Two divisions and one square root per configuration instead of four and one; each value is
// within a few ulp of the model's expression (tests/batch_convert_test.cpp). What remains is
// bound by the two atan calls (~4 cycles per value each); memory traffic at 10^7 configurations
// hides behind them. Ordinary stores, not non-temporal ones: the outputs are read again soon
// (the Monte Carlo's next stage, the caller's table).
void Avx2ConvertApparatus(std::size_t n, const double* L, const double* H, const double* D,
                          double a, double b, double* theta, double* alpha, double* x_eq) {
  const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5), two = _mm256_set1_pd(2.0);
  const __m256d c = _mm256_set1_pd(a / (2 * b)), two_b = _mm256_set1_pd(2 * b);
  for (std::size_t i = 0; i < n; i += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - i);
    const __m256d l = Load(L, i, m, 1.0), h = Load(H, i, m, 0.0), d = Load(D, i, m, 0.1);
    const __m256d inv = _mm256_div_pd(one, l);
    if (theta) Store(theta, i, m, _ZGVdN4v_atan(_mm256_mul_pd(h, inv)));
    if (alpha) Store(alpha, i, m, _mm256_mul_pd(two, _ZGVdN4v_atan(_mm256_mul_pd(_mm256_mul_pd(d, inv), half))));
    if (x_eq) {
      const __m256d cd = _mm256_mul_pd(c, d);
      const __m256d s = _mm256_sqrt_pd(_mm256_fmadd_pd(cd, cd, _mm256_mul_pd(h, h)));
      Store(x_eq, i, m, _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(two_b, h), l), _mm256_mul_pd(d, s)));
    }
  }
}

#pragma GCC pop_options
#endif  // UPHILL_BATCH_AVX2

}  // namespace

// The stage kernels write B and T only where the caller asked for them; a caller that wants
// neither still needs them internally for φ, so they go through a small stack block then.
namespace {
constexpr std::size_t kBlock = 256;  // 2 KiB per array: a stage's working set stays in L1

template <typename Run>
void WithSlopes(std::size_t n, const RailsArrays& out, Run run) {
  if (out.tan_theta && out.tan_half_alpha) {
    run(0, n, out, out.tan_theta, out.tan_half_alpha);
    return;
  }
  double B[kBlock], T[kBlock];
  for (std::size_t i = 0; i < n; i += kBlock) {
    const std::size_t m = std::min(kBlock, n - i);
    RailsArrays part;
    part.theta = out.theta ? out.theta + i : nullptr;
    part.alpha = out.alpha ? out.alpha + i : nullptr;
    part.phi = out.phi ? out.phi + i : nullptr;
    run(i, m, part, out.tan_theta ? out.tan_theta + i : B,
        out.tan_half_alpha ? out.tan_half_alpha + i : T);
  }
}
}  // namespace

void RailsFromApparatusBatch(std::size_t n, const double* L, const double* H, const double* D,
                             LConvention convention, const RailsArrays& out, VectorKernel kernel) {
  const bool avx2 = UseAvx2(kernel);
  WithSlopes(n, out, [&](std::size_t i, std::size_t m, const RailsArrays& o, double* B, double* T) {
#if UPHILL_BATCH_AVX2
    if (avx2) return Avx2RailsFromApparatus(m, L + i, H + i, D + i, convention, o, B, T);
#endif
    (void)avx2;
    ScalarRailsFromApparatus(m, L + i, H + i, D + i, convention, o, B, T);
  });
}

void RailsFromAnglesBatch(std::size_t n, const double* theta, const double* alpha,
                          const RailsArrays& out, VectorKernel kernel) {
  const bool avx2 = UseAvx2(kernel);
  WithSlopes(n, out, [&](std::size_t i, std::size_t m, const RailsArrays& o, double* B, double* T) {
#if UPHILL_BATCH_AVX2
    if (avx2) return Avx2RailsFromAngles(m, theta + i, alpha + i, o, B, T);
#endif
    (void)avx2;
    ScalarRailsFromAngles(m, theta + i, alpha + i, o, B, T);
  });
}

void SpheroidBatch(std::size_t n, const double* a, const double* b, const double* rod_radius,
                   const double* tan_theta, const double* tan_half_alpha, double* x_eq,
                   double* x_max, VectorKernel kernel) {
#if UPHILL_BATCH_AVX2
  if (UseAvx2(kernel))
    return Avx2Spheroid(n, a, b, rod_radius, tan_theta, tan_half_alpha, x_eq, x_max);
#else
  UseAvx2(kernel);
#endif
  ScalarSpheroid(n, a, b, rod_radius, tan_theta, tan_half_alpha, x_eq, x_max);
}

void DoubleConeBatch(std::size_t n, const double* R, const double* h, const double* tan_theta,
                     const double* tan_half_alpha, double* x_fall, double* theta0, double* q,
                     VectorKernel kernel) {
#if UPHILL_BATCH_AVX2
  if (UseAvx2(kernel))
    return Avx2DoubleCone(n, R, h, tan_theta, tan_half_alpha, x_fall, theta0, q);
#else
  UseAvx2(kernel);
#endif
  ScalarDoubleCone(n, R, h, tan_theta, tan_half_alpha, x_fall, theta0, q);
}

void ConvertApparatusBatch(std::size_t n, const double* L, const double* H, const double* D,
                           double a, double b, double* theta, double* alpha, double* x_eq,
                           VectorKernel kernel) {
#if UPHILL_BATCH_AVX2
  if (UseAvx2(kernel)) return Avx2ConvertApparatus(n, L, H, D, a, b, theta, alpha, x_eq);
#endif
  // Scalar: block-wise through the two stages (the model's expressions): B, T and the broadcast
  // a, b live in L1 between them.
  double B[kBlock], T[kBlock], av[kBlock], bv[kBlock];
  std::fill_n(av, kBlock, a);
  std::fill_n(bv, kBlock, b);
  for (std::size_t i = 0; i < n; i += kBlock) {
    const std::size_t m = std::min(kBlock, n - i);
    RailsArrays rails;
    rails.theta = theta ? theta + i : nullptr;
    rails.alpha = alpha ? alpha + i : nullptr;
    rails.tan_theta = B;
    rails.tan_half_alpha = T;
    RailsFromApparatusBatch(m, L + i, H + i, D + i, LConvention::kHorizontal, rails, kernel);
    if (x_eq) SpheroidBatch(m, av, bv, nullptr, B, T, x_eq + i, nullptr, kernel);
  }
}

}  // namespace uphill
