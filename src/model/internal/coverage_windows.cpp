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

// The values of one group of four that lie inside a window.
void Keep(Window (&w)[2], const double* group) {
  for (int lane = 0; lane < 4; ++lane) Keep(w, group[lane]);
}

// Counts and keeps one block's values for both windows of an output, and the shifted sums.
void CountWindowsScalar(Window (&w)[2], const double* y, std::size_t n, BlockSums* sums) {
  const double lo0 = w[0].lo, hi0 = w[0].hi, lo1 = w[1].lo, hi1 = w[1].hi;
  std::uint64_t below0 = 0, below1 = 0;
  double a = 0.0, b = 0.0;
  const double shift = sums ? sums->shift : 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double v = y[j];
    below0 += v < lo0;
    below1 += v < lo1;
    if ((v >= lo0 && v <= hi0) || (v >= lo1 && v <= hi1)) Keep(w, v);  // ~3 % of the values
    const double d = v - shift;
    a += d;
    b += d * d;
  }
  w[0].below += below0;
  w[1].below += below1;
  if (sums) {
    sums->sum += a;
    sums->sum2 += b;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)  // the pragma and __builtin_cpu_supports
#define UPHILL_WINDOWS_AVX2 1
// AVX2 by pragma, not by a per-file -mavx2 (see batch_convert.cpp for why); reached only after
// the run-time CPU check.
#pragma GCC push_options
#pragma GCC target("avx2,fma")
void CountWindowsAvx2(Window (&w)[2], const double* y, std::size_t n, BlockSums* sums) {
  // With ordered, disjoint windows lo0 ≤ hi0 < lo1 ≤ hi1 (always, but for a tiny pilot) four
  // comparisons per value give everything: y is in window 0 iff y ≥ lo0 and not y > hi0, and
  // #(y < lo) = n − #(y ≥ lo), counted as -1 masks. A group of four values with none inside a
  // window (≈ 90 % of groups: each window holds ≈ 1 % of the values) costs no branch mispredict;
  // the others keep their values one by one.
  if (!(w[0].hi < w[1].lo)) return CountWindowsScalar(w, y, n, sums);
  const __m256d lo0 = _mm256_set1_pd(w[0].lo), hi0 = _mm256_set1_pd(w[0].hi);
  const __m256d lo1 = _mm256_set1_pd(w[1].lo), hi1 = _mm256_set1_pd(w[1].hi);
  const __m256d shift = _mm256_set1_pd(sums ? sums->shift : 0.0);
  __m256i ge0 = _mm256_setzero_si256(), ge1 = _mm256_setzero_si256();
  // Two sets of sums: the additions' latency, not their count, would bound one set. The groups of
  // four holding a value inside a window are only noted here (branch-free: the index is always
  // written, the count advances when there is one) and kept afterwards, so that the loop has no
  // call and no unpredictable branch.
  __m256d a0 = _mm256_setzero_pd(), a1 = a0, b0 = a0, b1 = a0;
  std::uint32_t hit[1024 / 4 + 1];  // + 1: the slot written after the last hit
  std::size_t hits = 0;
  auto step = [&](std::size_t at, __m256d& a, __m256d& b) {
    const __m256d v = _mm256_loadu_pd(y + at);
    const __m256d g0 = _mm256_cmp_pd(v, lo0, _CMP_GE_OQ), g1 = _mm256_cmp_pd(v, hi0, _CMP_GT_OQ);
    const __m256d g2 = _mm256_cmp_pd(v, lo1, _CMP_GE_OQ), g3 = _mm256_cmp_pd(v, hi1, _CMP_GT_OQ);
    ge0 = _mm256_sub_epi64(ge0, _mm256_castpd_si256(g0));
    ge1 = _mm256_sub_epi64(ge1, _mm256_castpd_si256(g2));
    const __m256d d = _mm256_sub_pd(v, shift);
    a = _mm256_add_pd(a, d);
    b = _mm256_fmadd_pd(d, d, b);
    const __m256d inside = _mm256_or_pd(_mm256_andnot_pd(g1, g0), _mm256_andnot_pd(g3, g2));
    hit[hits] = static_cast<std::uint32_t>(at);
    hits += !_mm256_testz_pd(inside, inside);
  };
  std::size_t j = 0;
  while (n - j >= 8) {  // rounds of at most 1024 values: `hit` has room for each group of one
    const std::size_t stop = j + std::min<std::size_t>(1024, (n - j) & ~std::size_t{7});
    for (; j < stop; j += 8) {
      step(j, a0, b0);
      step(j + 4, a1, b1);
    }
    for (std::size_t h = 0; h < hits; ++h) Keep(w, y + hit[h]);
    hits = 0;
  }
  alignas(32) long long c0[4], c1[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(c0), ge0);
  _mm256_store_si256(reinterpret_cast<__m256i*>(c1), ge1);
  w[0].below += j - static_cast<std::uint64_t>(c0[0] + c0[1] + c0[2] + c0[3]);
  w[1].below += j - static_cast<std::uint64_t>(c1[0] + c1[1] + c1[2] + c1[3]);
  if (sums) {
    alignas(32) double sa[4], sb[4];
    _mm256_store_pd(sa, _mm256_add_pd(a0, a1));
    _mm256_store_pd(sb, _mm256_add_pd(b0, b1));
    sums->sum += (sa[0] + sa[1]) + (sa[2] + sa[3]);
    sums->sum2 += (sb[0] + sb[1]) + (sb[2] + sb[3]);
  }
  CountWindowsScalar(w, y + j, n - j, sums);
}
#pragma GCC pop_options
#else
#define UPHILL_WINDOWS_AVX2 0
#endif

}  // namespace

void CountWindows(Window (&w)[2], const double* y, std::size_t n, VectorKernel kernel, BlockSums* sums) {
#if UPHILL_WINDOWS_AVX2
  if (kernel != VectorKernel::kScalar && CpuHasAvx2Fma()) return CountWindowsAvx2(w, y, n, sums);
#endif
  (void)kernel;
  CountWindowsScalar(w, y, n, sums);
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
