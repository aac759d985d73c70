#include "narrow_atan.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "model/libmvec_avx2.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define UPHILL_NARROW_ATAN_AVX2 1
#else
#define UPHILL_NARROW_ATAN_AVX2 0
#endif

namespace uphill::internal {

NarrowAtan::NarrowAtan(double centre) : centre_(centre) {
  const long double c = centre, s = 1.0L + c * c;
  rho_ = static_cast<double>(std::sqrt(s));
  const long double f0 = std::atan(c);
  f0_hi_ = static_cast<double>(f0);
  f0_lo_ = static_cast<double>(f0 - f0_hi_);
  long double g_2 = 0.0L, g_1 = 0.0L;  // g_{j−2}, g_{j−1}
  for (int j = 0; j < kMaxDegree; ++j) {
    const long double g = ((j == 0 ? 1.0L : 0.0L) - 2.0L * c * g_1 - g_2) / s;
    coef_[j + 1] = static_cast<double>(g / (j + 1));
    g_2 = g_1;
    g_1 = g;
  }
}

int NarrowAtan::DegreeFor(double lo, double hi) const {
  if (!(lo > 0.0) || !(hi >= lo) || !std::isfinite(hi)) return 0;
  const double q = std::max(centre_ - lo, hi - centre_) / rho_;  // r/ρ
  if (!(q < 0.5)) return 0;
  // atan(lo) from below without calling atan (a call per block and angle, cold in the caches, cost
  // ~1 % of a Monte Carlo trial): atan(c) − (c − lo)/(1 + lo²) for lo < c (atan' ≤ 1/(1 + lo²) on
  // [lo, c]); the call only where that bound is poor. A smaller goal can only raise the degree.
  const double f0 = f0_hi_ * (1 - 0x1p-52);
  const double bound = lo >= centre_ ? f0 : f0 - (centre_ - lo) / (1.0 + lo * lo);
  const double goal = 0x1p-56 * (bound >= 0.5 * f0 ? bound : std::atan(lo));
  double power = q;  // (r/ρ)^(n+1)
  for (int n = 1; n <= kMaxDegree; ++n) {
    power *= q;
    if (power / ((n + 1) * (1.0 - q)) <= goal) return n;
  }
  return 0;
}

#if UPHILL_NARROW_ATAN_AVX2
namespace {
#pragma GCC push_options
#pragma GCC target("avx2,fma")

// avx2::Atan<N> over groups of four, two groups per step; a short tail is padded with the centre.
template <int N>
void Horner(std::size_t n, const double* x, double scale, double* y, const NarrowAtan& f) {
  const __m256d s = _mm256_set1_pd(scale);
  std::size_t j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256d ya = avx2::Atan<N>(f, _mm256_loadu_pd(x + j), s);
    const __m256d yb = avx2::Atan<N>(f, _mm256_loadu_pd(x + j + 4), s);
    _mm256_storeu_pd(y + j, ya);
    _mm256_storeu_pd(y + j + 4, yb);
  }
  for (; j < n; j += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - j);
    alignas(32) double t[4] = {f.centre(), f.centre(), f.centre(), f.centre()};
    for (std::size_t k = 0; k < m; ++k) t[k] = x[j + k];
    _mm256_store_pd(t, avx2::Atan<N>(f, _mm256_load_pd(t), s));
    for (std::size_t k = 0; k < m; ++k) y[j + k] = t[k];
  }
}

#if UPHILL_LIBMVEC_AVX2
void LibmvecAvx2(std::size_t n, const double* x, double scale, double* y) {
  const __m256d s = _mm256_set1_pd(scale);
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) _mm256_storeu_pd(y + j, _mm256_mul_pd(s, _ZGVdN4v_atan(_mm256_loadu_pd(x + j))));
  if (j < n) {  // padded, as batch_convert.cpp's tails
    alignas(32) double t[4] = {0.1, 0.1, 0.1, 0.1};
    for (std::size_t k = j; k < n; ++k) t[k - j] = x[k];
    _mm256_store_pd(t, _mm256_mul_pd(s, _ZGVdN4v_atan(_mm256_load_pd(t))));
    for (std::size_t k = j; k < n; ++k) y[k] = t[k - j];
  }
}
#endif

template <int... N>
void HornerOf(int degree, std::integer_sequence<int, N...>, std::size_t n, const double* x, double scale,
              double* y, const NarrowAtan& f) {
  ((degree == N + 1 ? Horner<N + 1>(n, x, scale, y, f) : void()), ...);
}

#pragma GCC pop_options
}  // namespace
#endif

void NarrowAtan::Evaluate(std::size_t n, const double* x, double scale, double* y, int degree) const {
#if UPHILL_NARROW_ATAN_AVX2
  HornerOf(degree, std::make_integer_sequence<int, kMaxDegree>{}, n, x, scale, y, *this);
#else
  for (std::size_t j = 0; j < n; ++j) {
    const double d = x[j] - centre_;
    double p = coef_[degree];
    for (int k = degree - 1; k >= 1; --k) p = std::fma(p, d, coef_[k]);
    y[j] = (f0_hi_ + std::fma(p, d, f0_lo_)) * scale;
  }
#endif
}

void NarrowAtan::Libmvec(std::size_t n, const double* x, double scale, double* y) {
#if UPHILL_NARROW_ATAN_AVX2 && UPHILL_LIBMVEC_AVX2
  LibmvecAvx2(n, x, scale, y);
#else
  for (std::size_t j = 0; j < n; ++j) y[j] = scale * std::atan(x[j]);
#endif
}

}  // namespace uphill::internal
