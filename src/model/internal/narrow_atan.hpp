// Internal to src/model: atan over a narrow interval by its Taylor polynomial, for the Monte
// Carlo's angles θ = atan(B), α = 2·atan(T), φ = atan(T/sqrt(1 + B²)) (monte_carlo.cpp).
//
// Why: a block of Monte Carlo trials draws each argument from a narrow interval around one value
// (a few standard uncertainties, typically under 1 % of it). There atan is a short polynomial in
// d = x − c about a fixed centre c: degree 6–7 for the lab case, a few fused multiply-adds and no
// division, where libmvec's general atan (reduction, division, longer polynomial) cost a fifth of
// a trial.
//
// The polynomial. atan(c + d) = Σ_k f_k d^k with f_0 = atan(c) and f_k = g_{k−1}/k, where g_j are
// the Taylor coefficients of atan' = 1/(1 + x²) at c: (1 + c²)g_j = [j = 0] − 2c·g_{j−1} − g_{j−2}.
// They are computed in long double; f_0 is kept as a double-double (hi + lo). Since
// 1/(1 + x²) = Im(1/(x − i)), |g_j| ≤ ρ^−(j+1) with ρ = |c − i| = sqrt(1 + c²), so for |d| ≤ r < ρ
// the truncation after degree n is at most (r/ρ)^(n+1) / ((n + 1)(1 − r/ρ)).
//
// Accuracy: DegreeFor picks the smallest degree whose truncation bound is ≤ 2^-56·atan(lo) over
// the interval [lo, hi] (0 < lo); the value is then hi_0 + (lo_0 + d·P(d)), so its error is the
// last addition's rounding (≤ 1/2 ulp) plus the truncation (≤ 1/8 ulp) plus the rounding of the
// correction d·P(d) (a few ulp of |d|/(1 + c²), which is small against atan(x) when the interval
// is narrow). tests/narrow_atan_test.cpp measures it against long double atanl: within 0.6 ulp
// over the lab case's intervals (±6 standard uncertainties), within 1.1 ulp over intervals ±30 %
// wide; libmvec's bound is 4 ulp.
//
// Each value depends only on x, the centre and the degree: the caller fixes the centre once per
// run and the degree per block from the block's own arguments, so results are reproducible.
#pragma once

#include <cstddef>

namespace uphill::internal {

class NarrowAtan {
 public:
  static constexpr int kMaxDegree = 16;

  NarrowAtan() = default;
  // The Taylor coefficients of atan about `centre` (finite, > 0).
  explicit NarrowAtan(double centre);

  double centre() const { return centre_; }

  // The smallest degree 1 … kMaxDegree whose truncation bound over [lo, hi] is ≤ 2^-56·a, a a
  // lower bound of atan(lo) (below it by at most 2c(c − lo)²/(1 + c²)², c the centre; atan(lo)
  // itself where that bound is poor), or 0 when there is none (the interval is too wide, or lo ≤ 0, or not finite): the caller then
  // uses another atan.
  int DegreeFor(double lo, double hi) const;

  // y[j] = scale·atan(x[j]), j < n, by the polynomial of `degree` (≥ 1, from DegreeFor on an
  // interval that holds every x[j]). scale = 1 or 2 (exact). AVX2 + FMA code: call only where
  // the CPU has them (UseAvx2). x and y may be the same array.
  void Evaluate(std::size_t n, const double* x, double scale, double* y, int degree) const;

  // y[j] = scale·atan(x[j]), j < n, by libmvec's AVX2 atan (the numbers of batch_convert.hpp's
  // kernels), where no degree suffices. AVX2 + FMA code, as Evaluate.
  static void Libmvec(std::size_t n, const double* x, double scale, double* y);

  // For the vector form below: f_0 = hi + lo, and f_k = coefficient(k), k ≥ 1.
  double f0_hi() const { return f0_hi_; }
  double f0_lo() const { return f0_lo_; }
  double coefficient(int k) const { return coef_[k]; }

 private:
  double centre_ = 0.0, rho_ = 1.0;
  double f0_hi_ = 0.0, f0_lo_ = 0.0;       // atan(centre) = f0_hi_ + f0_lo_
  double coef_[kMaxDegree + 1] = {};       // coef_[k] = f_k, k ≥ 1
};

}  // namespace uphill::internal

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace uphill::internal::avx2 {
// scale·atan(x) lane by lane by the polynomial of degree N: Evaluate's operations in Evaluate's
// order (Evaluate runs this), for a caller's own loop. AVX2 + FMA code: call only after the
// run-time check.
template <int N>
inline __m256d Atan(const NarrowAtan& f, __m256d x, __m256d scale) {
  const __m256d d = _mm256_sub_pd(x, _mm256_set1_pd(f.centre()));
  __m256d p = _mm256_set1_pd(f.coefficient(N));
  for (int k = N - 1; k >= 1; --k) p = _mm256_fmadd_pd(p, d, _mm256_set1_pd(f.coefficient(k)));
  return _mm256_mul_pd(_mm256_add_pd(_mm256_set1_pd(f.f0_hi()), _mm256_fmadd_pd(p, d, _mm256_set1_pd(f.f0_lo()))),
                       scale);
}
}  // namespace uphill::internal::avx2
#pragma GCC pop_options
#endif
