#include "model/gaussian_stream.hpp"

#include <Random123/philox.h>

#include <boost/random/normal_distribution.hpp>
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

// Boost's normal_distribution reads the engine through this view of the stream's buffer, so the
// scalar path and the vector path's fallback consume exactly the outputs Boost would.
struct GaussianStreamAccess {
  using result_type = std::uint64_t;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~result_type{0}; }
  GaussianStream* s;
  result_type operator()() {
    if (s->pos_ == s->end_) s->Refill();
    return s->buffer_[s->pos_++];
  }
  static double Next(GaussianStream* stream) {
    // A 64-bit engine (0 .. 2^64 − 1): Boost takes its fast 64-bit path.
    GaussianStreamAccess engine{stream};
    return boost::random::normal_distribution<double>()(engine);
  }
  static std::size_t Available(const GaussianStream* s) { return s->end_ - s->pos_; }
  static const std::uint64_t* Peek(const GaussianStream* s) { return s->buffer_ + s->pos_; }
  static void Skip(GaussianStream* s, std::size_t k) { s->pos_ += k; }
};

namespace {

// Blocks [first, first + count) of the stream (gaussian_stream.hpp), two words each, by
// Random123's own Philox4x32-10.
void PhiloxBlocks(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                  std::uint64_t* words) {
  const r123::Philox4x32 philox;
  const r123::Philox4x32::key_type k = {{key[0], key[1]}};
  for (std::size_t b = 0; b < count; ++b) {
    const std::uint64_t j = first + b;
    const r123::Philox4x32::ctr_type c = {{static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(j >> 32), id, 0}};
    const r123::Philox4x32::ctr_type r = philox(c, k);
    words[2 * b] = r.v[0] | (std::uint64_t{r.v[1]} << 32);
    words[2 * b + 1] = r.v[2] | (std::uint64_t{r.v[3]} << 32);
  }
}

#if UPHILL_NORMALS_AVX2
#pragma GCC push_options
#pragma GCC target("avx2")

// (hi, lo) of the eight 32 × 32-bit products m·x, lane by lane.
inline void MulHiLo(__m256i x, __m256i m, __m256i* hi, __m256i* lo) {
  const __m256i even = _mm256_mul_epu32(x, m);                         // lanes 0, 2, 4, 6
  const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(x, 32), m);  // lanes 1, 3, 5, 7
  *lo = _mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA);
  *hi = _mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xAA);
}

// PhiloxBlocks for 32 blocks at a time: Random123's rounds (philox.h: _philox4x32round, bumpkey)
// on vector lanes, block b in lane b % 8 of set b / 8 (four independent sets hide the multiplies'
// latency). Falls back to PhiloxBlocks where j's low word would wrap.
void PhiloxBlocksAvx2(std::uint64_t first, std::size_t count, const std::uint32_t key[2], std::uint32_t id,
                      std::uint64_t* words) {
  constexpr int kSets = 4;
  std::size_t b = 0;
  const __m256i m0 = _mm256_set1_epi32(static_cast<int>(PHILOX_M4x32_0));
  const __m256i m1 = _mm256_set1_epi32(static_cast<int>(PHILOX_M4x32_1));
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (; b + 8 * kSets <= count; b += 8 * kSets) {
    const std::uint64_t j = first + b;
    if (static_cast<std::uint32_t>(j) > 0xFFFFFFFFu - 8 * kSets) {
      PhiloxBlocks(j, 8 * kSets, key, id, words + 2 * b);
      continue;
    }
    __m256i x0[kSets], x1[kSets], x2[kSets], x3[kSets];
    for (int s = 0; s < kSets; ++s) {
      x0[s] = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j) + 8u * s)), lane);
      x1[s] = _mm256_set1_epi32(static_cast<int>(static_cast<std::uint32_t>(j >> 32)));
      x2[s] = _mm256_set1_epi32(static_cast<int>(id));
      x3[s] = _mm256_setzero_si256();
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
      // Words 2b = c0 | c1 << 32 and 2b + 1 = c2 | c3 << 32, per block, in block order.
      const __m256i a_lo = _mm256_unpacklo_epi32(x0[s], x1[s]);  // blocks 0,1 | 4,5
      const __m256i a_hi = _mm256_unpackhi_epi32(x0[s], x1[s]);  // blocks 2,3 | 6,7
      const __m256i b_lo = _mm256_unpacklo_epi32(x2[s], x3[s]), b_hi = _mm256_unpackhi_epi32(x2[s], x3[s]);
      const __m256i p0 = _mm256_unpacklo_epi64(a_lo, b_lo), q0 = _mm256_unpackhi_epi64(a_lo, b_lo);  // 0|4, 1|5
      const __m256i p1 = _mm256_unpacklo_epi64(a_hi, b_hi), q1 = _mm256_unpackhi_epi64(a_hi, b_hi);  // 2|6, 3|7
      __m256i* out = reinterpret_cast<__m256i*>(words + 2 * (b + 8 * s));
      _mm256_storeu_si256(out + 0, _mm256_permute2x128_si256(p0, q0, 0x20));  // blocks 0, 1
      _mm256_storeu_si256(out + 1, _mm256_permute2x128_si256(p1, q1, 0x20));  // blocks 2, 3
      _mm256_storeu_si256(out + 2, _mm256_permute2x128_si256(p0, q0, 0x31));  // blocks 4, 5
      _mm256_storeu_si256(out + 3, _mm256_permute2x128_si256(p1, q1, 0x31));  // blocks 6, 7
    }
  }
  PhiloxBlocks(first + b, count - b, key, id, words + 2 * b);
}

#pragma GCC pop_options
#endif  // UPHILL_NORMALS_AVX2

}  // namespace

void GaussianStream::Refill() {
  const std::size_t left = end_ - pos_;
  std::memmove(buffer_, buffer_ + pos_, left * sizeof buffer_[0]);
  const std::size_t blocks = (kBuffer - left) / 2;
#if UPHILL_NORMALS_AVX2
  if (avx2_) {
    PhiloxBlocksAvx2(next_block_, blocks, key_, id_, buffer_ + left);
  } else {
    PhiloxBlocks(next_block_, blocks, key_, id_, buffer_ + left);
  }
#else
  PhiloxBlocks(next_block_, blocks, key_, id_, buffer_ + left);
#endif
  next_block_ += blocks;
  pos_ = 0;
  end_ = left + 2 * blocks;
}

namespace {

#if UPHILL_NORMALS_AVX2
#pragma GCC push_options
// No "fma": nothing here may be contracted, the values must be Boost's to the bit.
#pragma GCC target("avx2")

// Boost 1.74's unit_normal_distribution fast path for a 64-bit engine (detail/int_float_pair.hpp,
// normal_distribution.hpp), four outputs u at a time:
//   bucket = u & 0xFF; i = bucket >> 1; sign = bucket & 1 ? +1 : −1
//   r = double((u & ~(1 << 11)) >> 8) · 2^-56     (the int → double conversion rounds to nearest)
//   x = r · table_x[i]; accepted iff x < table_x[i + 1]; value x·sign.
// The 56-bit integer is converted exactly as cvtsi2sd does: high and low 32-bit halves are exact
// doubles, and their sum hi·2^32 + lo is rounded once. Returns the accepted lanes as a bit mask.
int FastNormals4(const std::uint64_t* u, double* z) {
  const double* table_x = boost::random::detail::normal_table<double>::table_x;
  const __m256i raw = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(u));
  const __m256i bucket = _mm256_and_si256(raw, _mm256_set1_epi64x(0xFF));
  const __m256i bits = _mm256_srli_epi64(_mm256_andnot_si256(_mm256_set1_epi64x(1 << 11), raw), 8);
  // 2^52 + k as a double is exact for k < 2^32: the classic exact uint32 → double conversion.
  const __m256i magic = _mm256_set1_epi64x(0x4330000000000000LL);
  const __m256d two52 = _mm256_set1_pd(4503599627370496.0);
  const __m256d lo = _mm256_sub_pd(
      _mm256_castsi256_pd(_mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi64x(0xFFFFFFFFLL)), magic)),
      two52);
  const __m256d hi = _mm256_sub_pd(
      _mm256_castsi256_pd(_mm256_or_si256(_mm256_srli_epi64(bits, 32), magic)), two52);
  const __m256d r = _mm256_mul_pd(
      _mm256_add_pd(_mm256_mul_pd(hi, _mm256_set1_pd(4294967296.0)), lo),
      _mm256_set1_pd(1.0 / 72057594037927936.0));  // 2^-56
  // Table lookups by scalar loads: AVX2 gathers are slower than four loads on current x86 cores.
  const std::size_t i0 = (u[0] & 0xFF) >> 1, i1 = (u[1] & 0xFF) >> 1, i2 = (u[2] & 0xFF) >> 1,
                    i3 = (u[3] & 0xFF) >> 1;
  const __m256d x = _mm256_mul_pd(r, _mm256_set_pd(table_x[i3], table_x[i2], table_x[i1], table_x[i0]));
  const __m256d next = _mm256_set_pd(table_x[i3 + 1], table_x[i2 + 1], table_x[i1 + 1], table_x[i0 + 1]);
  const int accepted = _mm256_movemask_pd(_mm256_cmp_pd(x, next, _CMP_LT_OQ));
  // sign −1 (bucket bit 0 clear): flip the sign bit, which is what x·(−1.0) does, also for 0.
  const __m256i minus = _mm256_slli_epi64(
      _mm256_xor_si256(_mm256_and_si256(bucket, _mm256_set1_epi64x(1)), _mm256_set1_epi64x(1)), 63);
  _mm256_storeu_pd(z, _mm256_xor_pd(x, _mm256_castsi256_pd(minus)));
  return accepted;
}

void Avx2Normals(GaussianStream* stream, std::size_t n, double* z) {
  std::size_t k = 0;
  while (k + 4 <= n) {
    if (GaussianStreamAccess::Available(stream) < 4) {
      z[k++] = GaussianStreamAccess::Next(stream);  // refills the buffer, keeping order
      continue;
    }
    const int accepted = FastNormals4(GaussianStreamAccess::Peek(stream), z + k);
    if (accepted == 0xF) {
      GaussianStreamAccess::Skip(stream, 4);
      k += 4;
      continue;
    }
    // Lanes before the first rejected one are final; Boost produces the rejected one.
    const int good = __builtin_ctz(~accepted & 0xF);
    GaussianStreamAccess::Skip(stream, static_cast<std::size_t>(good));
    k += static_cast<std::size_t>(good);
    z[k++] = GaussianStreamAccess::Next(stream);
  }
  for (; k < n; ++k) z[k] = GaussianStreamAccess::Next(stream);
}

#pragma GCC pop_options
#endif  // UPHILL_NORMALS_AVX2

}  // namespace

void GaussianStream::Fill(std::size_t n, double* z, VectorKernel kernel) {
#if UPHILL_NORMALS_AVX2
  avx2_ = UseAvx2(kernel);
  if (avx2_) return Avx2Normals(this, n, z);
#else
  UseAvx2(kernel);
#endif
  for (std::size_t k = 0; k < n; ++k) z[k] = GaussianStreamAccess::Next(this);
}

}  // namespace uphill
