#include "model/gaussian_stream.hpp"

#include <Random123/philox.h>

#include <algorithm>
#include <cmath>
#include <cstring>

// The AVX2 kernels need no libmvec (integer and IEEE arithmetic only); whether they run is still
// the one kernel choice of vector_kernel.hpp.
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define UPHILL_NORMALS_AVX2 1
#else
#define UPHILL_NORMALS_AVX2 0
#endif

namespace uphill {

namespace {

// Blocks [first, first + count) of the stream (gaussian_stream.hpp) by Random123's own
// Philox4x32-10: block b's outputs c0 … c3 as words[4b … 4b + 3].
void PhiloxBlocks(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                  std::uint32_t lane3, std::uint32_t* words) {
  const r123::Philox4x32 philox;
  const r123::Philox4x32::key_type k = {{key[0], key[1]}};
  for (std::size_t b = 0; b < count; ++b) {
    const std::uint64_t j = first + b;
    const r123::Philox4x32::ctr_type c = {{static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(j >> 32), id, lane3}};
    const r123::Philox4x32::ctr_type r = philox(c, k);
    for (int l = 0; l < 4; ++l) words[4 * b + l] = r.v[l];
  }
}

#if UPHILL_NORMALS_AVX2
#pragma GCC push_options
#pragma GCC target("avx2")

// (hi, lo) of the eight 32 × 32-bit products m·x, lane by lane, both from the two widening
// multiplies by shifts and blends: the multiplier is the scarce unit (on AMD Zen 3 the low
// multiply instead of the shift and blend for lo measured ≈ 1.5 % slower per Monte Carlo trial).
inline void MulHiLo(__m256i x, __m256i m, __m256i* hi, __m256i* lo) {
  const __m256i even = _mm256_mul_epu32(x, m);                         // lanes 0, 2, 4, 6
  const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(x, 32), m);  // lanes 1, 3, 5, 7
  *lo = _mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA);
  *hi = _mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xAA);
}

// PhiloxBlocks for 8·kSets blocks at a time: Random123's rounds (philox.h: _philox4x32round,
// bumpkey) on vector lanes, block b in lane b % 8 of set b / 8 (independent sets hide the
// multiplies' latency; three rather than four keep the state in registers: fewer spills, faster).
// Blocks left over go through one set, then PhiloxBlocks, which also takes over where j's low word
// would wrap.
template <int kSets>
std::size_t PhiloxSetsAvx2(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                           std::uint32_t lane3, std::uint32_t* words) {
  std::size_t b = 0;
  const __m256i m0 = _mm256_set1_epi32(static_cast<int>(PHILOX_M4x32_0));
  const __m256i m1 = _mm256_set1_epi32(static_cast<int>(PHILOX_M4x32_1));
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (; b + 8 * kSets <= count; b += 8 * kSets) {
    const std::uint64_t j = first + b;
    if (static_cast<std::uint32_t>(j) > 0xFFFFFFFFu - 8 * kSets) {
      PhiloxBlocks(j, 8 * kSets, key, id, lane3, words + 4 * b);
      continue;
    }
    __m256i x0[kSets], x1[kSets], x2[kSets], x3[kSets];
    for (int s = 0; s < kSets; ++s) {
      x0[s] = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j) + 8u * s)), lane);
      x1[s] = _mm256_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j >> 32)));
      x2[s] = _mm256_set1_epi32(static_cast<int>(id));
      x3[s] = _mm256_set1_epi32(static_cast<int>(lane3));
    }
    std::uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < 10; ++round) {
      if (round > 0) k0 += PHILOX_W32_0, k1 += PHILOX_W32_1;
      const __m256i key0 = _mm256_set1_epi32(static_cast<int>(k0)), key1 = _mm256_set1_epi32(static_cast<int>(k1));
      for (int s = 0; s < kSets; ++s) {
        __m256i hi0, lo0, hi1, lo1;
        MulHiLo(x0[s], m0, &hi0, &lo0);
        MulHiLo(x2[s], m1, &hi1, &lo1);
        x0[s] = _mm256_xor_si256(_mm256_xor_si256(hi1, x1[s]), key0);
        x1[s] = lo1;
        x2[s] = _mm256_xor_si256(_mm256_xor_si256(hi0, x3[s]), key1);
        x3[s] = lo0;
      }
    }
    for (int s = 0; s < kSets; ++s) {
      // Words 4b … 4b + 3 = c0 … c3, per block, in block order (as the 64-bit lanes c0 | c1 << 32
      // and c2 | c3 << 32: x86 is little-endian).
      const __m256i a_lo = _mm256_unpacklo_epi32(x0[s], x1[s]);  // blocks 0,1 | 4,5
      const __m256i a_hi = _mm256_unpackhi_epi32(x0[s], x1[s]);  // blocks 2,3 | 6,7
      const __m256i b_lo = _mm256_unpacklo_epi32(x2[s], x3[s]), b_hi = _mm256_unpackhi_epi32(x2[s], x3[s]);
      const __m256i p0 = _mm256_unpacklo_epi64(a_lo, b_lo), q0 = _mm256_unpackhi_epi64(a_lo, b_lo);  // 0|4, 1|5
      const __m256i p1 = _mm256_unpacklo_epi64(a_hi, b_hi), q1 = _mm256_unpackhi_epi64(a_hi, b_hi);  // 2|6, 3|7
      __m256i* out = reinterpret_cast<__m256i*>(words + 4 * (b + 8 * s));
      _mm256_storeu_si256(out + 0, _mm256_permute2x128_si256(p0, q0, 0x20));  // blocks 0, 1
      _mm256_storeu_si256(out + 1, _mm256_permute2x128_si256(p1, q1, 0x20));  // blocks 2, 3
      _mm256_storeu_si256(out + 2, _mm256_permute2x128_si256(p0, q0, 0x31));  // blocks 4, 5
      _mm256_storeu_si256(out + 3, _mm256_permute2x128_si256(p1, q1, 0x31));  // blocks 6, 7
    }
  }
  return b;
}

void PhiloxBlocksAvx2(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                      std::uint32_t lane3, std::uint32_t* words) {
  std::size_t b = PhiloxSetsAvx2<3>(first, count, key, id, lane3, words);
  b += PhiloxSetsAvx2<1>(first + b, count - b, key, id, lane3, words + 4 * b);
  PhiloxBlocks(first + b, count - b, key, id, lane3, words + 4 * b);
}

#pragma GCC pop_options
#endif  // UPHILL_NORMALS_AVX2

#if UPHILL_NORMALS_AVX2
#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC diagnostic push
// GCC 12's own avx512fintrin.h (_mm512_set1_epi32 on an undefined vector) trips this warning.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

// PhiloxBlocksAvx2 with 512-bit vectors: 64 blocks at a time, block b in lane b % 16 of set b / 16;
// the round's three-way xors by one ternary-logic instruction each (0x96: a ^ b ^ c). Words in
// the same order. Falls back to PhiloxBlocks where j's low word would wrap.
void PhiloxBlocksAvx512(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                        std::uint32_t lane3, std::uint32_t* words) {
  constexpr int kSets = 4;
  std::size_t b = 0;
  const __m512i m0 = _mm512_set1_epi32(static_cast<int>(PHILOX_M4x32_0));
  const __m512i m1 = _mm512_set1_epi32(static_cast<int>(PHILOX_M4x32_1));
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  for (; b + 16 * kSets <= count; b += 16 * kSets) {
    const std::uint64_t j = first + b;
    if (static_cast<std::uint32_t>(j) > 0xFFFFFFFFu - 16 * kSets) {
      PhiloxBlocks(j, 16 * kSets, key, id, lane3, words + 4 * b);
      continue;
    }
    __m512i x0[kSets], x1[kSets], x2[kSets], x3[kSets];
    for (int s = 0; s < kSets; ++s) {
      x0[s] = _mm512_add_epi32(_mm512_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j) + 16u * s)), lane);
      x1[s] = _mm512_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j >> 32)));
      x2[s] = _mm512_set1_epi32(static_cast<int>(id));
      x3[s] = _mm512_set1_epi32(static_cast<int>(lane3));
    }
    std::uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < 10; ++round) {
      if (round > 0) k0 += PHILOX_W32_0, k1 += PHILOX_W32_1;
      const __m512i key0 = _mm512_set1_epi32(static_cast<int>(k0)), key1 = _mm512_set1_epi32(static_cast<int>(k1));
      for (int s = 0; s < kSets; ++s) {
        // (hi, lo) of the 32 × 32-bit products, lane by lane, as MulHiLo does.
        const __m512i even0 = _mm512_mul_epu32(x0[s], m0), odd0 = _mm512_mul_epu32(_mm512_srli_epi64(x0[s], 32), m0);
        const __m512i even1 = _mm512_mul_epu32(x2[s], m1), odd1 = _mm512_mul_epu32(_mm512_srli_epi64(x2[s], 32), m1);
        const __m512i lo0 = _mm512_mask_blend_epi32(0xAAAA, even0, _mm512_slli_epi64(odd0, 32));
        const __m512i hi0 = _mm512_mask_blend_epi32(0xAAAA, _mm512_srli_epi64(even0, 32), odd0);
        const __m512i lo1 = _mm512_mask_blend_epi32(0xAAAA, even1, _mm512_slli_epi64(odd1, 32));
        const __m512i hi1 = _mm512_mask_blend_epi32(0xAAAA, _mm512_srli_epi64(even1, 32), odd1);
        x0[s] = _mm512_ternarylogic_epi32(hi1, x1[s], key0, 0x96);
        x1[s] = lo1;
        x2[s] = _mm512_ternarylogic_epi32(hi0, x3[s], key1, 0x96);
        x3[s] = lo0;
      }
    }
    for (int s = 0; s < kSets; ++s) {
      // Per 128-bit lane L (blocks 4L … 4L + 3): words c0 | c1 << 32 and c2 | c3 << 32 per block.
      const __m512i a_lo = _mm512_unpacklo_epi32(x0[s], x1[s]), a_hi = _mm512_unpackhi_epi32(x0[s], x1[s]);
      const __m512i b_lo = _mm512_unpacklo_epi32(x2[s], x3[s]), b_hi = _mm512_unpackhi_epi32(x2[s], x3[s]);
      const __m512i p = _mm512_unpacklo_epi64(a_lo, b_lo), q = _mm512_unpackhi_epi64(a_lo, b_lo);  // blocks 4L, 4L+1
      const __m512i r = _mm512_unpacklo_epi64(a_hi, b_hi), t = _mm512_unpackhi_epi64(a_hi, b_hi);  // 4L+2, 4L+3
      // A 4 × 4 transpose of 128-bit lanes puts the blocks in order.
      const __m512i u0 = _mm512_shuffle_i64x2(p, q, 0x44), u1 = _mm512_shuffle_i64x2(r, t, 0x44);
      const __m512i u2 = _mm512_shuffle_i64x2(p, q, 0xEE), u3 = _mm512_shuffle_i64x2(r, t, 0xEE);
      std::uint32_t* out = words + 4 * (b + 16 * s);
      _mm512_storeu_si512(out + 0, _mm512_shuffle_i64x2(u0, u1, 0x88));   // blocks 0 … 3
      _mm512_storeu_si512(out + 16, _mm512_shuffle_i64x2(u0, u1, 0xDD));  // blocks 4 … 7
      _mm512_storeu_si512(out + 32, _mm512_shuffle_i64x2(u2, u3, 0x88));  // blocks 8 … 11
      _mm512_storeu_si512(out + 48, _mm512_shuffle_i64x2(u2, u3, 0xDD));  // blocks 12 … 15
    }
  }
  PhiloxBlocksAvx2(first + b, count - b, key, id, lane3, words + 4 * b);
}

#pragma GCC diagnostic pop
#pragma GCC pop_options

bool CpuHasAvx512f() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}
#endif  // UPHILL_NORMALS_AVX2

// Blocks by the widest code the Fill's kernel allows (gaussian_stream.hpp: all give the same words).
void PhiloxBlocksBy(int simd, std::uint64_t first, std::size_t count, const std::uint32_t key[2],
                    std::uint32_t id, std::uint32_t lane3, std::uint32_t* words) {
#if UPHILL_NORMALS_AVX2
  if (simd == 2) return PhiloxBlocksAvx512(first, count, key, id, lane3, words);
  if (simd == 1) return PhiloxBlocksAvx2(first, count, key, id, lane3, words);
#endif
  (void)simd;
  PhiloxBlocks(first, count, key, id, lane3, words);
}


// The fast path's two numbers per layer side by side (one 16-byte load per word): x_i·2^-22
// (exact: a power-of-two scaling of a normal double) and x_{i+1}.
struct alignas(16) LayerPair {
  double scale, next;
};
struct FastTable {
  LayerPair layer[ziggurat::kLayers];
  constexpr FastTable() : layer() {
    for (int i = 0; i < ziggurat::kLayers; ++i)
      layer[i] = {ziggurat::kX[i] * 0x1p-22, ziggurat::kX[i + 1]};
  }
};
constexpr FastTable kFast;
constexpr std::uint64_t kLayerMask = ziggurat::kLayers - 1;
static_assert((ziggurat::kLayers & kLayerMask) == 0 && kLayerMask == 1023,
              "the stream's definition uses 10 bits for the layer, bit 10 for the sign");

// 2m + 1 for the word's position m = ⌊w / 2^11⌋: ⌊w / 2^10⌋ is 2m + (the sign bit); its bit 0 set.
inline std::uint32_t OddPosition(std::uint32_t w) { return (w >> 10) | 1u; }

// The fast path of gaussian_stream.hpp for one word: *z = ±x, true when accepted.
inline bool FastPath(std::uint32_t w, double* z) {
  const LayerPair& p = kFast.layer[w & kLayerMask];
  const double x = static_cast<double>(OddPosition(w)) * p.scale;  // < 2^22: converted exactly
  *z = (w >> 10) & 1 ? -x : x;
  return x < p.next;
}

// The wedge test y < exp(−(x·x)·0.5) of layer i ≥ 1 for x and the side word's u, settled without
// exp where a bound suffices. On a layer where f(x) = exp(−x²/2) has one curvature (convex for
// x ≥ 1, concave for x ≤ 1), f lies between its chord through the layer's corners,
// f_i + (x_i − x)·(f_{i+1} − f_i)/(x_i − x_{i+1}), and its tangent at x_i, f_i + (x_i − x)·x_i·f_i.
// A y below both by a relative 2^-30 is accepted, one above both by as much rejected; only the
// rest (≈ 6 % of wedge tests, most in the top layers) and the layer holding x = 1 call exp. The
// margin dwarfs every rounding (the tables', the bounds', exp's ulp): the decisions are exp's own
// and the stream is unchanged. Why: the rare exp call finds the C library's code and tables
// evicted from the caches, and cost more per trial than a deviate's whole fast path. x_i and
// x_{i+1} come from kFast (in cache: the fast path reads it), f from the stream's table.
inline bool WedgeAccepts(std::size_t i, double x, double u) {
  const double x_i = kFast.layer[i].scale * 0x1p22, x_next = kFast.layer[i].next;  // exact
  const double df = ziggurat::kF[i + 1] - ziggurat::kF[i];
  const double y = ziggurat::kF[i] + u * df;
  if (x_next >= 1.0 || x_i <= 1.0) {
    const double t = x_i - x;
    const double chord = ziggurat::kF[i] + t * (df / (x_i - x_next));
    const double tangent = ziggurat::kF[i] + t * (x_i * ziggurat::kF[i]);
    if (y < std::min(chord, tangent) * (1 - 0x1p-30)) return true;
    if (y > std::max(chord, tangent) * (1 + 0x1p-30)) return false;
  }
  return y < std::exp(-(x * x) * 0.5);
}

}  // namespace

void GaussianStream::Refill() {
  const std::size_t left = end_ - pos_;
  std::memmove(buffer_, buffer_ + pos_, left * sizeof buffer_[0]);
  const std::size_t blocks = (kBuffer - left) / 4;
  PhiloxBlocksBy(simd_, next_block_, blocks, key_, id_, 0, buffer_ + left);
  next_block_ += blocks;
  pos_ = 0;
  end_ = left + 4 * blocks;
}

void GaussianStream::RefillSide() {
  constexpr std::size_t blocks = kSideBuffer / 2;
  PhiloxBlocksBy(simd_, next_side_block_, blocks, key_, id_, 1, side_);
  next_side_block_ += blocks;
  side_pos_ = 0;
}

// The slow path of gaussian_stream.hpp for main word w whose fast path rejected: wedge, tail and
// retries, reading side words in order.
struct GaussianStreamAccess {
  template <bool kScale>
  static void Fill(GaussianStream* s, std::size_t n, double mean, double scale, double* out, VectorKernel kernel,
                   GaussianStream::Range* range);
  static double SlowPath(GaussianStream* s, std::uint32_t w) {
    for (;;) {
      const std::size_t i = w & kLayerMask;
      const bool negative = (w >> 10) & 1;
      const double x = static_cast<double>(OddPosition(w)) * kFast.layer[i].scale;
      if (x < kFast.layer[i].next) return negative ? -x : x;  // a retry's fast path
      if (i == 0) {
        for (;;) {
          const double a = static_cast<double>((s->NextSide() >> 11) + 1) * 0x1p-53;
          const double b = static_cast<double>((s->NextSide() >> 11) + 1) * 0x1p-53;
          const double xi = -std::log(a) / ziggurat::kR;
          const double eta = -std::log(b);
          if (eta + eta > xi * xi) return negative ? -(ziggurat::kR + xi) : ziggurat::kR + xi;
        }
      }
      const double u = static_cast<double>(s->NextSide() >> 11) * 0x1p-53;
      if (WedgeAccepts(i, x, u)) return negative ? -x : x;
      w = static_cast<std::uint32_t>(s->NextSide());  // its low 32 bits
    }
  }
};

namespace {

// Deviates (kScale: mean + scale·z) for the words w[0 … n), fast path only; the offsets of the
// rejected words are appended to `rejected`, and their outputs are to be overwritten.
// *range grows to contain every output written (also those to be overwritten: it may be wider
// than the final values, never narrower).
template <bool kScale>
std::size_t FastScalar(const std::uint32_t* w, std::size_t n, double mean, double scale, double* out,
                       std::uint32_t* rejected, GaussianStream::Range* range) {
  std::size_t count = 0;
  double lo = range->min, hi = range->max;
  for (std::size_t j = 0; j < n; ++j) {
    double z;
    if (!FastPath(w[j], &z)) rejected[count++] = static_cast<std::uint32_t>(j);
    out[j] = kScale ? mean + scale * z : z;
    lo = std::min(lo, out[j]);
    hi = std::max(hi, out[j]);
  }
  *range = {lo, hi};
  return count;
}

#if UPHILL_NORMALS_AVX2
#pragma GCC push_options
// No "fma": nothing here may be contracted; the values must be the scalar code's to the bit.
#pragma GCC target("avx2")

// FastScalar four words at a time, the same operations lane by lane, each word widened to a 64-bit
// lane: the 22-bit 2m + 1 becomes a double exactly as 2^52 + (2m + 1) (its bits OR-ed into 2^52's)
// minus 2^52; bit 10 moved to the sign bit is the negation; the table pair of each lane by one
// 16-byte load (scalar loads beat AVX2 gathers on current x86 cores).
template <bool kScale>
std::size_t FastAvx2(const std::uint32_t* w, std::size_t n, double mean, double scale, double* out,
                     std::uint32_t* rejected, GaussianStream::Range* range) {
  __m256d lo = _mm256_set1_pd(range->min), hi = _mm256_set1_pd(range->max);
  const __m256i magic = _mm256_set1_epi64x(0x4330000000000001LL);  // 2^52, and the 1 of 2m + 1
  const __m256d two52 = _mm256_set1_pd(0x1p52);
  const __m256i sign_bit = _mm256_set1_epi64x(static_cast<long long>(1ULL << 63));
  const __m256d vmean = _mm256_set1_pd(mean), vscale = _mm256_set1_pd(scale);
  const double* table = &kFast.layer[0].scale;
  std::size_t count = 0, j = 0;
  for (; j + 4 <= n; j += 4) {
    const __m256i word = _mm256_cvtepu32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(w + j)));
    const __m128d p0 = _mm_load_pd(table + 2 * (w[j] & kLayerMask));
    const __m128d p1 = _mm_load_pd(table + 2 * (w[j + 1] & kLayerMask));
    const __m128d p2 = _mm_load_pd(table + 2 * (w[j + 2] & kLayerMask));
    const __m128d p3 = _mm_load_pd(table + 2 * (w[j + 3] & kLayerMask));
    const __m256d p02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(p0), p2, 1);  // s0 n0 s2 n2
    const __m256d p13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(p1), p3, 1);  // s1 n1 s3 n3
    const __m256d lane_scale = _mm256_unpacklo_pd(p02, p13), next = _mm256_unpackhi_pd(p02, p13);
    const __m256d m = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(_mm256_srli_epi64(word, 10), magic)), two52);
    const __m256d x = _mm256_mul_pd(m, lane_scale);
    const int accepted = _mm256_movemask_pd(_mm256_cmp_pd(x, next, _CMP_LT_OQ));
    __m256d z = _mm256_xor_pd(x, _mm256_castsi256_pd(_mm256_and_si256(_mm256_slli_epi64(word, 53), sign_bit)));
    if (kScale) z = _mm256_add_pd(vmean, _mm256_mul_pd(vscale, z));
    _mm256_storeu_pd(out + j, z);
    lo = _mm256_min_pd(lo, z);
    hi = _mm256_max_pd(hi, z);
    if (__builtin_expect(accepted != 0xF, 0))
      for (int lane = 0; lane < 4; ++lane)
        if (!(accepted & (1 << lane))) rejected[count++] = static_cast<std::uint32_t>(j + lane);
  }
  alignas(32) double l[4], h[4];
  _mm256_store_pd(l, lo);
  _mm256_store_pd(h, hi);
  *range = {std::min(std::min(l[0], l[1]), std::min(l[2], l[3])),
            std::max(std::max(h[0], h[1]), std::max(h[2], h[3]))};
  const std::size_t tail = FastScalar<kScale>(w + j, n - j, mean, scale, out + j, rejected + count, range);
  for (std::size_t t = count; t < count + tail; ++t) rejected[t] += static_cast<std::uint32_t>(j);
  return count + tail;
}

#pragma GCC pop_options

#endif  // UPHILL_NORMALS_AVX2

}  // namespace

// Fill and FillScaled: the main words in the buffer's chunks, the fast path over each chunk, then
// its rejected words in order (so the side words are read in the deviates' order).
template <bool kScale>
void GaussianStreamAccess::Fill(GaussianStream* s, std::size_t n, double mean, double scale, double* out,
                                VectorKernel kernel, GaussianStream::Range* range) {
  *range = {HUGE_VAL, -HUGE_VAL};
  const bool avx2 = UseAvx2(kernel);
#if UPHILL_NORMALS_AVX2
  s->simd_ = !avx2 ? 0 : kernel == VectorKernel::kAuto && CpuHasAvx512f() ? 2 : 1;
#else
  (void)avx2;
#endif
  std::uint32_t rejected[GaussianStream::kBuffer];
  for (std::size_t k = 0; k < n;) {
    if (s->pos_ == s->end_) s->Refill();
    const std::size_t c = std::min(s->end_ - s->pos_, n - k);
    const std::uint32_t* w = s->buffer_ + s->pos_;
#if UPHILL_NORMALS_AVX2
    // The fast path stays four-wide with AVX-512 too: eight-wide needs gathers, which cost more.
    const std::size_t r = s->simd_ > 0 ? FastAvx2<kScale>(w, c, mean, scale, out + k, rejected, range)
                                       : FastScalar<kScale>(w, c, mean, scale, out + k, rejected, range);
#else
    const std::size_t r = FastScalar<kScale>(w, c, mean, scale, out + k, rejected, range);
#endif
    for (std::size_t t = 0; t < r; ++t) {
      const double z = SlowPath(s, w[rejected[t]]);
      const double y = kScale ? mean + scale * z : z;
      out[k + rejected[t]] = y;
      *range = {std::min(range->min, y), std::max(range->max, y)};
    }
    s->pos_ += c;
    k += c;
  }
}

void GaussianStream::Fill(std::size_t n, double* z, VectorKernel kernel) {
  Range range;
  GaussianStreamAccess::Fill<false>(this, n, 0.0, 1.0, z, kernel, &range);
}

GaussianStream::Range GaussianStream::FillScaled(std::size_t n, double mean, double scale, double* y,
                                                 VectorKernel kernel) {
  Range range;
  GaussianStreamAccess::Fill<true>(this, n, mean, scale, y, kernel, &range);
  return range;
}

}  // namespace uphill
