// GaussianStream: the Monte Carlo's source of standard normal deviates, reproducible and fast.
//
// The stream, exactly (so that a result can be reproduced elsewhere). Stream `id` of seed s has
// the 32-bit main words w_0, w_1, … (lane 3 of the counter = 0) and the 64-bit side words q_0,
// q_1, … (lane 3 = 1): for block j = 0, 1, 2, … and lane3 ∈ {0, 1}
//     (c0, c1, c2, c3) = Philox4x32-10(counter = (j mod 2^32, ⌊j / 2^32⌋, id, lane3),
//                                      key = (s mod 2^32, ⌊s / 2^32⌋)),
//     main words w_4j … w_4j+3 = c0, c1, c2, c3                                      (lane3 = 0),
//     side words q_2j = c0 + 2^32·c1,  q_2j+1 = c2 + 2^32·c3                       (lane3 = 1),
// Philox4x32 with 10 rounds as Random123 defines it (r123::Philox4x32; Salmon, Moraes, Dror,
// Shaw, "Parallel random numbers: as easy as 1, 2, 3", SC 2011; Debian librandom123-dev).
//
// Deviate z_k comes from main word w_k by a 1024-layer ziggurat (Marsaglia & Tsang, "The
// ziggurat method for generating random variables", J. Stat. Softw. 5(8), 2000) with the tables
// x_i, f_i of gaussian_stream_tables.hpp (N = 1024, R, V; their definition is stated in
// tools/ziggurat_tables.py, which wrote them, and recomputed by tests/gaussian_stream_test.cpp):
//   i = w mod 1024 (the layer), sign = bit 10 of w (1: negative), m = ⌊w / 2^11⌋ (21 bits),
//   x = (2m + 1) · (x_i · 2^-22)   (one IEEE double multiplication; 2m + 1 and x_i·2^-22 are
//                                   exact: x is the centre of the m-th of 2^21 equal parts of
//                                   [0, x_i), rounded once)
//   fast path: if x < x_{i+1}, z = ±x.                                 (≈ 99.57 % of the words)
//   otherwise, reading side words in order (the side sequence is shared by all the stream's
//   deviates: z_k's rejected fast path reads after z_{k−1}'s):
//     i = 0 (the base layer, x ≥ R: the tail): repeat { a = (⌊q/2^11⌋ + 1)·2^-53,
//         b = (⌊q'/2^11⌋ + 1)·2^-53 from the next two side words; ξ = −log(a)/R; η = −log(b) }
//         until η + η > ξ·ξ; z = ±(R + ξ)  (the sign of the word that chose layer 0);
//     i ≥ 1 (a wedge): u = ⌊q/2^11⌋·2^-53 from the next side word; y = f_i + u·(f_{i+1} − f_i);
//         if y < exp(−(x·x)·0.5), z = ±x;
//     otherwise the next side word's low 32 bits, q mod 2^32, take the place of w (a new layer,
//     sign and m) and the fast path test and this paragraph repeat.
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
// CPU with AVX-512F, 64 blocks at a time on 512-bit lanes; kAvx2 keeps to AVX2) and finishes the
// rare rejected words afterwards from the side words, without disturbing the main words' one-
// word-per-deviate order. One 32-bit word per deviate (not 64): Philox, the largest cost of a
// Monte Carlo trial, runs half as often, for a position resolved to 2^-21 of its layer's width
// (below). 1024 layers (not the paper's 128 or 256): the fast path accepts 99.57 % of words rather
// than 98.5 % (256), for 24 KB of tables. The wedge test calls exp only where a chord or tangent
// of exp(−x²/2) with a wide margin cannot decide it (≈ 6 % of wedge tests): the decisions are
// exp's own, and the rare call, cold in the caches, no longer costs more than the fast path.
//
// Accuracy: the deviates follow N(0, 1) up to the ziggurat's exactness (the layers' areas agree
// to ~2e-15) and the position's resolution: inside layer i the values are the 2^21 centres of
// equal parts of [0, x_i), so a deviate is the exact ziggurat's value moved to the nearest centre,
// by at most x_i·2^-22 (≤ 1.0e-6, x_0 = 4.27), with no bias (centres) and a variance lower by the
// parts' own, x_i²·2^-44/3 (≤ 3.5e-13 of the unit variance): far below any Monte Carlo's
// statistical resolution; the tail beyond R and the wedges use 53-bit uniforms from the side
// words. tests/gaussian_stream_test.cpp checks 10^6 deviates against Boost.Math's normal CDF
// (Kolmogorov–Smirnov), their moments against the normal's, and the frequencies beyond 3 and
// 4 σ and R.
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
  static constexpr std::size_t kBuffer = 4096;     // main words: 16 KB, whole blocks (four each)
  static constexpr std::size_t kSideBuffer = 64;  // side words: 32 blocks
  void Refill();      // keeps the unread main words, tops the buffer up with whole blocks
  void RefillSide();  // the next kSideBuffer side words
  std::uint64_t NextSide() {
    if (side_pos_ == kSideBuffer) RefillSide();
    const std::size_t k = side_pos_++;
    return side_[2 * k] | std::uint64_t{side_[2 * k + 1]} << 32;
  }
  std::uint32_t key_[2];
  std::uint32_t id_;
  int simd_ = 0;  // the current Fill's code: 0 scalar (Random123's Philox), 1 AVX2, 2 AVX-512F
  std::uint64_t next_block_ = 0, next_side_block_ = 0;
  std::uint32_t buffer_[kBuffer] = {};
  std::size_t pos_ = 0, end_ = 0;  // unread main words: buffer_[pos_, end_)
  std::uint32_t side_[2 * kSideBuffer] = {};  // Philox outputs: side word k = side_[2k] + 2^32·side_[2k + 1]
  std::size_t side_pos_ = kSideBuffer;
};

}  // namespace uphill
