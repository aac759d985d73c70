#include "model/gaussian_stream.hpp"

#include <boost/random/normal_distribution.hpp>
#include <cstring>

// The AVX2 fast path needs no libmvec (integer and IEEE arithmetic only); whether it runs is
// still the one kernel choice of vector_kernel.hpp.
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
    // The same range as boost::random::mt19937_64 (0 .. 2^64 − 1): Boost sees the engine it would.
    GaussianStreamAccess engine{stream};
    return boost::random::normal_distribution<double>()(engine);
  }
  static std::size_t Available(const GaussianStream* s) { return s->end_ - s->pos_; }
  static const std::uint64_t* Peek(const GaussianStream* s) { return s->buffer_ + s->pos_; }
  static void Skip(GaussianStream* s, std::size_t k) { s->pos_ += k; }
};

void GaussianStream::Refill() {
  const std::size_t left = end_ - pos_;
  std::memmove(buffer_, buffer_ + pos_, left * sizeof buffer_[0]);
  // Through a local copy of the engine: its position index and the buffer are both unsigned long,
  // so with the member engine every buffer store could alias the index and the loop would run at
  // the speed of a store-to-load round trip. The copy (2.5 KB) costs far less than that.
  boost::random::mt19937_64 engine = engine_;
  for (std::size_t k = left; k < kBuffer; ++k) buffer_[k] = engine();
  engine_ = engine;
  pos_ = 0;
  end_ = kBuffer;
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
  if (UseAvx2(kernel)) return Avx2Normals(this, n, z);
#else
  UseAvx2(kernel);
#endif
  for (std::size_t k = 0; k < n; ++k) z[k] = GaussianStreamAccess::Next(this);
}

}  // namespace uphill
