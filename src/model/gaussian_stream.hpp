// GaussianStream: the Monte Carlo's source of standard normal deviates, reproducible and fast.
//
// The stream, exactly (so that a result can be reproduced elsewhere). Stream `id` of seed s has
// two sequences of 64-bit words, the main words w_0, w_1, … (lane 3 of the counter = 0) and the
// side words q_0, q_1, … (lane 3 = 1): for block j = 0, 1, 2, … and lane3 ∈ {0, 1}
//     (c0, c1, c2, c3) = Philox4x32-10(counter = (j mod 2^32, ⌊j / 2^32⌋, id, lane3),
//                                      key = (s mod 2^32, ⌊s / 2^32⌋)),
//     word 2j = c0 + 2^32·c1,   word 2j+1 = c2 + 2^32·c3,
// Philox4x32 with 10 rounds as Random123 defines it (r123::Philox4x32; Salmon, Moraes, Dror,
// Shaw, "Parallel random numbers: as easy as 1, 2, 3", SC 2011; Debian librandom123-dev).
//
// Deviate z_k comes from main word w_k by a 1024-layer ziggurat (Marsaglia & Tsang, "The
// ziggurat method for generating random variables", J. Stat. Softw. 5(8), 2000) with the tables
// x_i, f_i of gaussian_stream_tables.hpp (N = 1024, R, V; their definition is stated in
// tools/ziggurat_tables.py, which wrote them, and recomputed by tests/gaussian_stream_test.cpp):
//   i = w mod 1024 (the layer), sign = bit 10 of w (1: negative), m = ⌊w / 2^12⌋ (52 bits),
//   x = m · (x_i · 2^-52)            (one IEEE double multiplication; m and x_i·2^-52 are exact)
//   fast path: if x < x_{i+1}, z = ±x.                                 (≈ 99.57 % of the words)
//   otherwise, reading side words in order (the side sequence is shared by all the stream's
//   deviates: z_k's rejected fast path reads after z_{k−1}'s):
//     i = 0 (the base layer, x ≥ R: the tail): repeat { a = (⌊q/2^11⌋ + 1)·2^-53,
//         b = (⌊q'/2^11⌋ + 1)·2^-53 from the next two side words; ξ = −log(a)/R; η = −log(b) }
//         until η + η > ξ·ξ; z = ±(R + ξ)  (the sign of the word that chose layer 0);
//     i ≥ 1 (a wedge): u = ⌊q/2^11⌋·2^-53 from the next side word; y = f_i + u·(f_{i+1} − f_i);
//         if y < exp(−(x·x)·0.5), z = ±x;
//     otherwise the next side word takes the place of w (a new layer, sign and m) and the fast
//     path test and this paragraph repeat.
// Every operation is one IEEE double operation rounded to nearest, in the order written, with no
// fused multiply-add (the file is compiled with -ffp-contract=off). So the fast path, ≈ 99.6 % of
// the deviates, is bit for bit the same on every IEEE machine; the rare slow path (≈ 0.43 %)
// calls the C library's exp and log, whose last bit can differ between C libraries (glibc's are
// within 1 ulp), which can change a tail value's last bit or, with probability ~2^-52 per wedge
// test, a decision. Trial k depends only on (seed, id, k): a counter-based generator needs no
// state to skip ahead, and the CPU or the code (scalar, AVX2, AVX-512) changes nothing
// (tests/gaussian_stream_test.cpp compares every kernel with a plain reimplementation of this
// paragraph, 10^6 values, bit for bit).
//
// Why this shape: the fast path is a handful of integer and IEEE operations on one word, so the
// AVX2 kernel runs it four words at a time (Philox itself 24 blocks at a time, the same 32-bit
// multiplies and xors as Random123's scalar code, on vector lanes; with VectorKernel::kAuto on a
// CPU with AVX-512F, 64 blocks at a time on 512-bit lanes, Philox being most of the cost; kAvx2
// keeps to AVX2) and finishes the rare rejected
// words afterwards from the side words, without disturbing the main words' one-word-per-deviate
// order. 1024 layers (not the paper's 128 or 256): the fast path accepts 99.57 % of words rather
// than 98.5 % (256), for 24 KB of tables. The wedge test calls exp only where a chord or tangent
// of exp(−x²/2) with a wide margin cannot decide it (≈ 6 % of wedge tests): the decisions are
// exp's own, and the rare call, cold in the caches, no longer costs more than the fast path.
//
// Accuracy: the deviates follow N(0, 1) up to the ziggurat's exactness (the layers' areas agree
// to ~2e-15; the base layer's values are multiples of x_0·2^-52, other layers' of x_i·2^-52);
// tests/gaussian_stream_test.cpp checks 10^6 of them against Boost.Math's normal CDF
// (Kolmogorov–Smirnov) and the frequencies beyond 3 and 4 σ.
#pragma once

#include <cstddef>
#include <cstdint>

#include "model/gaussian_stream_tables.hpp"
#include "model/vector_kernel.hpp"

namespace uphill {

class GaussianStream {
 public:
  // Stream `id` of `seed` (see above).
  GaussianStream(std::uint64_t seed, std::uint32_t id)
      : key_{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}, id_(id) {}
  // The next n deviates z_k.
  void Fill(std::size_t n, double* z, VectorKernel kernel = VectorKernel::kAuto);
  // Bounds that contain every value of a fill (they may be wider, never narrower): a caller that
  // screens its draws against a domain checks two numbers instead of n.
  struct Range {
    double min = 0.0, max = 0.0;
  };
  // The next n deviates as mean + scale·z_k: one IEEE multiplication, then one addition.
  Range FillScaled(std::size_t n, double mean, double scale, double* y,
                   VectorKernel kernel = VectorKernel::kAuto);

 private:
  friend struct GaussianStreamAccess;
  static constexpr std::size_t kBuffer = 2048;     // main words: 16 KB, even (two per block)
  static constexpr std::size_t kSideBuffer = 64;  // side words: 32 blocks
  void Refill();      // keeps the unread main words, tops the buffer up with whole blocks
  void RefillSide();  // the next kSideBuffer side words
  std::uint64_t NextSide() {
    if (side_pos_ == kSideBuffer) RefillSide();
    return side_[side_pos_++];
  }
  std::uint32_t key_[2];
  std::uint32_t id_;
  int simd_ = 0;  // the current Fill's code: 0 scalar (Random123's Philox), 1 AVX2, 2 AVX-512F
  std::uint64_t next_block_ = 0, next_side_block_ = 0;
  std::uint64_t buffer_[kBuffer] = {};
  std::size_t pos_ = 0, end_ = 0;  // unread main words: buffer_[pos_, end_)
  std::uint64_t side_[kSideBuffer] = {};
  std::size_t side_pos_ = kSideBuffer;
};

}  // namespace uphill
