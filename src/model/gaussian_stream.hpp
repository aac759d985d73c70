// GaussianStream: the Monte Carlo's source of standard normal deviates, reproducible and fast.
//
// The stream, exactly (so that a result can be reproduced elsewhere): stream `id` of seed s is
// the sequence of 64-bit words w_0, w_1, … with, for block j = 0, 1, 2, …,
//     (c0, c1, c2, c3) = Philox4x32-10(counter = (j mod 2^32, ⌊j / 2^32⌋, id, 0),
//                                      key = (s mod 2^32, ⌊s / 2^32⌋)),
//     w_2j = c0 + 2^32·c1,   w_2j+1 = c2 + 2^32·c3,
// Philox4x32 with 10 rounds as Random123 defines it (r123::Philox4x32; Salmon, Moraes, Dror,
// Shaw, "Parallel random numbers: as easy as 1, 2, 3", SC 2011; Debian librandom123-dev). The
// deviates are what boost::random::normal_distribution<double> returns when it reads those words
// as a 64-bit engine (range 0 … 2^64 − 1): Boost's ziggurat (Boost 1.74's tables), bit for bit,
// whichever kernel runs (tests/batch_convert_test.cpp compares 10^6 values with Random123 +
// Boost). So the trials depend only on (seed, id) and the Boost version, not on the CPU or the
// C++ library; a counter-based generator also needs no state to skip ahead: block j is computed
// from j alone.
//
// Speed: the AVX2 kernel computes Philox for 32 blocks at once (the same 32-bit multiplies and
// xors as Random123's scalar code, on vector lanes) and evaluates the ziggurat's fast path
// (≈ 98.8 % of values: one word gives a layer index, a sign and a 53-bit fraction r;
// x = r·x[i] is accepted if x < x[i+1]; plain integer and IEEE arithmetic with correctly rounded
// conversions) for four words at once, with the same operations and Boost's own tables. At the
// first lane that the fast path rejects it lets Boost's normal_distribution itself produce that
// value from the same buffered words (wedge, tail, retries), then resumes. The scalar kernel calls
// r123::Philox4x32 and Boost directly.
#pragma once

#include <cstddef>
#include <cstdint>

#include "model/vector_kernel.hpp"

namespace uphill {

class GaussianStream {
 public:
  // Stream `id` of `seed` (see above).
  GaussianStream(std::uint64_t seed, std::uint32_t id)
      : key_{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}, id_(id) {}
  void Fill(std::size_t n, double* z, VectorKernel kernel = VectorKernel::kAuto);

 private:
  friend struct GaussianStreamAccess;
  static constexpr std::size_t kBuffer = 2048;  // 16 KB of words, even (two per block)
  void Refill();  // keeps the unread words, tops the buffer up with whole blocks
  std::uint32_t key_[2];
  std::uint32_t id_;
  std::uint64_t next_block_ = 0;
  bool avx2_ = false;  // the kernel of the current Fill
  std::uint64_t buffer_[kBuffer] = {};
  std::size_t pos_ = 0, end_ = 0;  // unread outputs: buffer_[pos_, end_)
};

}  // namespace uphill
