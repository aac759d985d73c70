#include "least_squares_moments.hpp"

#include <algorithm>

namespace uphill::internal {
namespace {

constexpr std::size_t kRows = 1024;  // per chunk (8 KB of each column)

struct Constants {
  double x0, y0, inv_sx, inv_sy;
};

// Adds one chunk's moments to acc (long double: the rounding of the sums stays at the level of one
// chunk's). `omp simd` (this file is built with -fopenmp-simd) lets the compiler keep the sums in
// vector lanes, and the AVX2 clone runs where the CPU has it; lanes change only the order of the
// additions.
template <bool kWeighted>
[[gnu::noinline, gnu::target_clones("avx2", "default")]] void ChunkMoments(const double* x, const double* y,
                                                                          const double* u, std::size_t m,
                                                                          Constants q, long double acc[6]) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5)
  for (std::size_t j = 0; j < m; ++j) {
    const double xs = (x[j] - q.x0) * q.inv_sx, ys = (y[j] - q.y0) * q.inv_sy;
    double w = 1.0;
    if constexpr (kWeighted) {
      const double us = u[j] * q.inv_sy;
      w = 1.0 / (us * us);
    }
    s0 += w, s1 += w * xs, s2 += w * ys, s3 += w * xs * xs, s4 += w * xs * ys, s5 += w * ys * ys;
  }
  acc[0] += s0, acc[1] += s1, acc[2] += s2, acc[3] += s3, acc[4] += s4, acc[5] += s5;
}

}  // namespace

LineMoments TakeMoments(const StandardisedView& v, bool weighted) {
  long double acc[6] = {0, 0, 0, 0, 0, 0};
  const Constants q{v.x0, v.y0, v.inv_sx, v.inv_sy};
  for (std::size_t i = 0; i < v.n; i += kRows) {
    const std::size_t m = std::min(kRows, v.n - i);
    if (weighted)
      ChunkMoments<true>(v.x + i, v.y + i, v.uy + i, m, q, acc);
    else
      ChunkMoments<false>(v.x + i, v.y + i, nullptr, m, q, acc);
  }
  return {static_cast<double>(acc[0]), static_cast<double>(acc[1]), static_cast<double>(acc[2]),
          static_cast<double>(acc[3]), static_cast<double>(acc[4]), static_cast<double>(acc[5])};
}

bool LeastSquaresCost::RowSums(const double* theta, bool /*with_hessian*/, LineSums* s) const {
  const double k = theta[0], c = theta[1];
  s->jtj << m_.xx, m_.x, m_.x, m_.w;
  s->jtr << -(m_.xy - c * m_.x - k * m_.xx), -(m_.y - c * m_.w - k * m_.x);
  s->rr = std::max(m_.yy - 2.0 * c * m_.y - 2.0 * k * m_.xy + c * c * m_.w + 2.0 * k * c * m_.x + k * k * m_.xx, 0.0);
  s->hessian = s->jtj;  // the residuals are linear in θ
  return true;
}

}  // namespace uphill::internal
