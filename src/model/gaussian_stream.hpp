// GaussianStream: the Monte Carlo's source of standard normal deviates, reproducible and fast.
//
// Contract: Fill(n, z) writes the next n values that
//     boost::random::normal_distribution<double> unit;  unit(engine)
// returns for a boost::random::mt19937_64 engine seeded with `seed`, bit for bit, whichever
// kernel runs (tests/batch_convert_test.cpp compares 10^6 values). So the trials depend only on
// the seed and the Boost version, not on the CPU or the C++ library (std::normal_distribution's
// algorithm is implementation-defined, which is why Boost's is used at all).
//
// Why not just call unit(engine): Boost's ziggurat is the largest part of a Monte Carlo trial.
// Its fast path (≈ 98.8 % of values: one 64-bit engine output gives a layer index, a sign and a
// 53-bit fraction r; x = r·x[i] is accepted if x < x[i+1]) is plain integer and IEEE arithmetic
// with correctly rounded conversions, so the AVX2 kernel evaluates it for four consecutive engine
// outputs at once, with the same operations and Boost's own tables. At the first lane that the
// fast path rejects it stops and lets Boost's normal_distribution itself produce that value from
// the same buffered engine outputs (wedge, tail, retries), then resumes. The engine is Boost's, called in a tight loop into a buffer.
#pragma once

#include <boost/random/mersenne_twister.hpp>
#include <cstddef>
#include <cstdint>

#include "model/vector_kernel.hpp"

namespace uphill {

class GaussianStream {
 public:
  explicit GaussianStream(std::uint64_t seed) : engine_(seed) {}
  void Fill(std::size_t n, double* z, VectorKernel kernel = VectorKernel::kAuto);

 private:
  friend struct GaussianStreamAccess;
  static constexpr std::size_t kBuffer = 2048;  // 16 KB: the engine copy in Refill amortised
  void Refill();  // keeps the unread outputs, tops the buffer up from the engine
  boost::random::mt19937_64 engine_;
  std::uint64_t buffer_[kBuffer] = {};
  std::size_t pos_ = 0, end_ = 0;  // unread outputs: buffer_[pos_, end_)
};

}  // namespace uphill
