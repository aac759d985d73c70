#include "coverage_windows.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace uphill::internal {
namespace {

void Keep(Window (&w)[2], double v) {
  for (Window& x : w)
    if (v >= x.lo && v <= x.hi) x.kept.Push(v);
}

// Counts and keeps one block's values for both windows of an output. Counts are exact integers
// and the kept values are appended in order, so both versions give identical results.
void CountWindowsScalar(Window (&w)[2], const double* y, std::size_t n) {
  const double lo0 = w[0].lo, hi0 = w[0].hi, lo1 = w[1].lo, hi1 = w[1].hi;
  std::uint64_t below0 = 0, below1 = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double v = y[j];
    below0 += v < lo0;
    below1 += v < lo1;
    if ((v >= lo0 && v <= hi0) || (v >= lo1 && v <= hi1)) Keep(w, v);  // ~3 % of the values
  }
  w[0].below += below0;
  w[1].below += below1;
}

#if defined(__x86_64__) && defined(__GNUC__)  // the pragma and __builtin_cpu_supports
#define UPHILL_WINDOWS_AVX2 1
// AVX2 by pragma, not by a per-file -mavx2 (see batch_convert.cpp for why); reached only after
// the run-time CPU check.
#pragma GCC push_options
#pragma GCC target("avx2")
// Left-packing permutations: for a 4-bit lane mask, the 32-bit lane indices that move the selected
// doubles to the front, in order.
struct PackTable {
  alignas(32) int idx[16][8];
  int count[16];
  constexpr PackTable() : idx(), count() {
    for (int m = 0; m < 16; ++m) {
      int k = 0;
      for (int lane = 0; lane < 4; ++lane)
        if (m & (1 << lane)) {
          idx[m][2 * k] = 2 * lane;
          idx[m][2 * k + 1] = 2 * lane + 1;
          ++k;
        }
      count[m] = k;
      for (; k < 4; ++k) idx[m][2 * k] = idx[m][2 * k + 1] = 0;
    }
  }
};
constexpr PackTable kPack;

void CountWindowsAvx2(Window (&w)[2], const double* y, std::size_t n) {
  // With ordered, disjoint windows lo0 ≤ hi0 < lo1 ≤ hi1 (always, but for a tiny pilot) four
  // comparisons per value give everything: y is in window 0 iff y ≥ lo0 and not y > hi0, and
  // #(y < lo) = n − #(y ≥ lo), counted as -1 masks. Every step stores its four values, left-
  // packed, at each window's end and advances by the number that qualified: no branch on data.
  if (!(w[0].hi < w[1].lo)) return CountWindowsScalar(w, y, n);
  const __m256d lo0 = _mm256_set1_pd(w[0].lo), hi0 = _mm256_set1_pd(w[0].hi);
  const __m256d lo1 = _mm256_set1_pd(w[1].lo), hi1 = _mm256_set1_pd(w[1].hi);
  w[0].kept.Reserve(n);
  w[1].kept.Reserve(n);
  double* end0 = w[0].kept.end();
  double* end1 = w[1].kept.end();
  __m256i ge0 = _mm256_setzero_si256(), ge1 = _mm256_setzero_si256();
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const __m256d v = _mm256_loadu_pd(y + j);
    const __m256d g0 = _mm256_cmp_pd(v, lo0, _CMP_GE_OQ), g1 = _mm256_cmp_pd(v, hi0, _CMP_GT_OQ);
    const __m256d g2 = _mm256_cmp_pd(v, lo1, _CMP_GE_OQ), g3 = _mm256_cmp_pd(v, hi1, _CMP_GT_OQ);
    ge0 = _mm256_sub_epi64(ge0, _mm256_castpd_si256(g0));
    ge1 = _mm256_sub_epi64(ge1, _mm256_castpd_si256(g2));
    const int m0 = _mm256_movemask_pd(_mm256_andnot_pd(g1, g0));
    const int m1 = _mm256_movemask_pd(_mm256_andnot_pd(g3, g2));
    const __m256i vi = _mm256_castpd_si256(v);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(end0),
                        _mm256_permutevar8x32_epi32(vi, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.idx[m0]))));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(end1),
                        _mm256_permutevar8x32_epi32(vi, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.idx[m1]))));
    end0 += kPack.count[m0];
    end1 += kPack.count[m1];
  }
  w[0].kept.SetEnd(end0);
  w[1].kept.SetEnd(end1);
  alignas(32) long long c0[4], c1[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(c0), ge0);
  _mm256_store_si256(reinterpret_cast<__m256i*>(c1), ge1);
  w[0].below += j - static_cast<std::uint64_t>(c0[0] + c0[1] + c0[2] + c0[3]);
  w[1].below += j - static_cast<std::uint64_t>(c1[0] + c1[1] + c1[2] + c1[3]);
  CountWindowsScalar(w, y + j, n - j);
}
#pragma GCC pop_options
#else
#define UPHILL_WINDOWS_AVX2 0
#endif

}  // namespace

void CountWindows(Window (&w)[2], const double* y, std::size_t n, VectorKernel kernel) {
#if UPHILL_WINDOWS_AVX2
  if (kernel != VectorKernel::kScalar && CpuHasAvx2Fma()) return CountWindowsAvx2(w, y, n);
#endif
  (void)kernel;
  CountWindowsScalar(w, y, n);
}

// JCGM 101 §7.7: q = pM if that is an integer, else int(pM + 1/2); r = (M − q)/2 rounded up;
// [y_(r), y_(r+q)], 1-based order statistics. Clamped into [1, M] for tiny M.
void CoverageRanks(std::uint64_t m, double p, std::uint64_t* low, std::uint64_t* high) {
  const double pm = p * static_cast<double>(m);
  std::uint64_t q = static_cast<std::uint64_t>(pm);
  if (static_cast<double>(q) != pm) q = static_cast<std::uint64_t>(pm + 0.5);
  q = std::min(q, m);
  const std::uint64_t r = std::max<std::uint64_t>((m - q + 1) / 2, 1);
  *low = r;
  *high = std::min(r + q, m);
}

std::optional<double> Select(Window& w, std::uint64_t k) {
  if (k <= w.below || k - w.below > w.kept.size()) return std::nullopt;
  double* const it = w.kept.begin() + (k - w.below - 1);
  std::nth_element(w.kept.begin(), it, w.kept.end());
  return *it;
}

}  // namespace uphill::internal
