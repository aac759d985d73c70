// Internal to src/model: the AVX2 + FMA expressions of the batch kernels (batch_convert.cpp) that
// the Monte Carlo's one-pass kernel (monte_carlo.cpp) evaluates too: one definition for both, so
// that a trial's values are the batch kernel's bit for bit whichever pass computed them. Each
// function carries its target (pragma), so a file may include this anywhere; call them only from
// AVX2 + FMA code reached after the run-time check (vector_kernel.hpp).
#pragma once

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace uphill::internal::avx2 {

// hypot(x, y) as sqrt(x² + y²) with one rounding inside: ≤ 1 ulp more than hypot, and safe here
// because the model's quantities are far from overflow and underflow (|x|, |y| in 1e-150..1e150).
inline __m256d Hypot(__m256d x, __m256d y) { return _mm256_sqrt_pd(_mm256_fmadd_pd(x, x, _mm256_mul_pd(y, y))); }

// B = tanθ = H/Lh and T = tan(α/2) = D/(2·Lh), from the horizontal distance Lh.
inline __m256d TanTheta(__m256d h, __m256d horizontal) { return _mm256_div_pd(h, horizontal); }
inline __m256d TanHalfAlpha(__m256d d, __m256d horizontal) {
  return _mm256_div_pd(d, _mm256_mul_pd(_mm256_set1_pd(2.0), horizontal));
}

// φ = atan(T/hypot(1, B)): the argument, with one rounding inside the square root.
inline __m256d PhiArgument(__m256d B, __m256d T) {
  return _mm256_div_pd(T, _mm256_sqrt_pd(_mm256_fmadd_pd(B, B, _mm256_set1_pd(1.0))));
}

// Spheroid (semi-axes a across, b along; a sphere: a = b = R) on line rails:
// A = a·T/b, x_eq = a·B/(A·hypot(A, B)), x_max = hypot(a, b/T).
inline __m256d SpheroidXEq(__m256d a, __m256d b, __m256d B, __m256d T) {
  const __m256d A = _mm256_div_pd(_mm256_mul_pd(a, T), b);
  return _mm256_div_pd(_mm256_mul_pd(a, B), _mm256_mul_pd(A, Hypot(A, B)));
}
inline __m256d SpheroidXMax(__m256d a, __m256d b, __m256d T) { return Hypot(a, _mm256_div_pd(b, T)); }

}  // namespace uphill::internal::avx2
#pragma GCC pop_options
#endif
