// glibc's libmvec vector variants (x86_64 "d" = AVX2 ABI, 4 doubles), for the vectorised kernels
// of the batch converter (model/batch_convert.cpp) and of ReleaseTimes (motion/release_times.cpp).
// Declared by hand rather than reached through <math.h>'s `#pragma omp declare simd` so that the
// choice does not depend on -ffast-math or -fopenmp-simd, which the project does not use.
// UPHILL_LIBMVEC_AVX2 is 1 where they exist (the target links libmvec and defines
// UPHILL_HAVE_LIBMVEC); callers choose at run time through vector_kernel.hpp.
// Accuracy: libmvec's documented bound, within 4 ulp of the correctly rounded result.
#pragma once

#if defined(UPHILL_HAVE_LIBMVEC) && defined(__x86_64__)
#include <immintrin.h>
#define UPHILL_LIBMVEC_AVX2 1
#pragma GCC push_options
#pragma GCC target("avx2,fma")
extern "C" __m256d _ZGVdN4v_atan(__m256d);
extern "C" __m256d _ZGVdN4v_tan(__m256d);
extern "C" __m256d _ZGVdN4v_sin(__m256d);
#pragma GCC pop_options
#else
#define UPHILL_LIBMVEC_AVX2 0
#endif
