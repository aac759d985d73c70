// The AVX2 kernels of the Monte Carlo propagation (monte_carlo.cpp), called where the processor
// has AVX2 and FMA (checked at run time). They evaluate the batch converter's own vector
// expressions (batch_kernels_avx2.hpp), so that a trial's value does not depend on the path that
// computed it.
#pragma once

#include <cstddef>

#include "narrow_atan.hpp"

namespace uphill::internal {

// A range of values, NaNs skipped.
struct Bounds {
  double lo, hi;
};

#if defined(__x86_64__) && defined(__GNUC__)
#pragma GCC push_options
#pragma GCC target("avx2,fma")
// φ's argument T/sqrt(1 + B²), the expression of batch_convert.cpp's AVX2 kernels, so that the
// angle is the only thing the vector path computes anew; and in the same pass the bounds of B, T
// and the argument (NaNs skipped), for NarrowAtan::DegreeFor.
void PhiArgumentAvx2(std::size_t n, const double* B, const double* T, double* out, Bounds (&bounds)[3]);

// The common case's model in one pass over a block: per group of four trials B, T, the three
// angles (NarrowAtan, all three at `degree`, 1 … NarrowAtan::kMaxDegree), x_eq and x_max by the
// batch kernels' own expressions, nothing going through memory in between. out: θ, α, φ, x_eq,
// x_max. A short tail is padded with the block's first trial.
void LineSpheroidOnePassAvx2(int degree, std::size_t n, const double* L, const double* H, const double* D,
                             const double* a, const double* b, const NarrowAtan (&atan)[3], double* const (&out)[5]);
#pragma GCC pop_options
#endif

}  // namespace uphill::internal
