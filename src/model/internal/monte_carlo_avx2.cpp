#include "monte_carlo_avx2.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "batch_kernels_avx2.hpp"

namespace uphill::internal {

#pragma GCC push_options
#pragma GCC target("avx2,fma")
void PhiArgumentAvx2(std::size_t n, const double* B, const double* T, double* out, Bounds (&bounds)[3]) {
  __m256d lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = _mm256_set1_pd(HUGE_VAL), hi[k] = _mm256_set1_pd(-HUGE_VAL);
  auto extend = [&](int k, __m256d v) {  // a NaN in v yields the second operand: skipped
    lo[k] = _mm256_min_pd(v, lo[k]);
    hi[k] = _mm256_max_pd(v, hi[k]);
  };
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const __m256d b = _mm256_loadu_pd(B + j), t = _mm256_loadu_pd(T + j);
    const __m256d p = avx2::PhiArgument(b, t);
    _mm256_storeu_pd(out + j, p);
    extend(0, b);
    extend(1, t);
    extend(2, p);
  }
  for (int k = 0; k < 3; ++k) {
    alignas(32) double l[4], h[4];
    _mm256_store_pd(l, lo[k]);
    _mm256_store_pd(h, hi[k]);
    bounds[k] = {std::min(std::min(l[0], l[1]), std::min(l[2], l[3])),
                 std::max(std::max(h[0], h[1]), std::max(h[2], h[3]))};
  }
  for (; j < n; ++j) {
    out[j] = T[j] / std::sqrt(std::fma(B[j], B[j], 1.0));
    const double v[3] = {B[j], T[j], out[j]};
    for (int k = 0; k < 3; ++k) {
      bounds[k].lo = v[k] < bounds[k].lo ? v[k] : bounds[k].lo;
      bounds[k].hi = v[k] > bounds[k].hi ? v[k] : bounds[k].hi;
    }
  }
}
namespace {

template <int N>
void LineSpheroidOnePassOfDegree(std::size_t n, const double* L, const double* H, const double* D, const double* a,
                             const double* b, const NarrowAtan (&atan)[3], double* const (&out)[5]) {
  const __m256d one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0);
  auto group = [&](__m256d l, __m256d h, __m256d d, __m256d va, __m256d vb, __m256d (&y)[5]) {
    const __m256d B = avx2::TanTheta(h, l), T = avx2::TanHalfAlpha(d, l);
    y[0] = avx2::Atan<N>(atan[0], B, one);
    y[1] = avx2::Atan<N>(atan[1], T, two);
    y[2] = avx2::Atan<N>(atan[2], avx2::PhiArgument(B, T), one);
    y[3] = avx2::SpheroidXEq(va, vb, B, T);
    y[4] = avx2::SpheroidXMax(va, vb, T);
  };
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    __m256d y[5];
    group(_mm256_loadu_pd(L + j), _mm256_loadu_pd(H + j), _mm256_loadu_pd(D + j), _mm256_loadu_pd(a + j),
          _mm256_loadu_pd(b + j), y);
    for (int k = 0; k < 5; ++k) _mm256_storeu_pd(out[k] + j, y[k]);
  }
  if (j < n) {
    alignas(32) double in[5][4];
    const double* from[5] = {L, H, D, a, b};
    for (int k = 0; k < 5; ++k)
      for (std::size_t t = 0; t < 4; ++t) in[k][t] = from[k][j + t < n ? j + t : 0];
    __m256d y[5];
    group(_mm256_load_pd(in[0]), _mm256_load_pd(in[1]), _mm256_load_pd(in[2]), _mm256_load_pd(in[3]),
          _mm256_load_pd(in[4]), y);
    for (int k = 0; k < 5; ++k) {
      alignas(32) double t[4];
      _mm256_store_pd(t, y[k]);
      for (std::size_t m = 0; j + m < n; ++m) out[k][j + m] = t[m];
    }
  }
}

template <int... N>
void LineSpheroidOnePassOf(int degree, std::integer_sequence<int, N...>, std::size_t n, const double* L,
                           const double* H, const double* D, const double* a, const double* b,
                           const NarrowAtan (&atan)[3], double* const (&out)[5]) {
  ((degree == N + 1 ? LineSpheroidOnePassOfDegree<N + 1>(n, L, H, D, a, b, atan, out) : void()), ...);
}

}  // namespace

void LineSpheroidOnePassAvx2(int degree, std::size_t n, const double* L, const double* H, const double* D,
                             const double* a, const double* b, const NarrowAtan (&atan)[3], double* const (&out)[5]) {
  LineSpheroidOnePassOf(degree, std::make_integer_sequence<int, NarrowAtan::kMaxDegree>{}, n, L, H, D, a, b, atan, out);
}
#pragma GCC pop_options

}  // namespace uphill::internal
#endif
