// Internal to src/model: the Monte Carlo's coverage intervals without sorting all M values
// (monte_carlo.cpp). For each end of an interval a window [lo, hi] placed by a pilot: values below
// it are only counted, values inside are kept; the order statistic is then selected among the
// kept values. Exact whenever the window holds the wanted rank (Select says when it does not).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>

#include "model/vector_kernel.hpp"

namespace uphill::internal {

// The kept values live in a plain growable array rather than a std::vector so that the AVX2 path
// can store four candidates unconditionally and advance by the number that qualified (branch-
// free), without zero-filling the slack as vector::resize would.
class Kept {
 public:
  std::size_t size() const { return size_; }
  double* begin() { return data_.get(); }
  double* end() { return data_.get() + size_; }
  // Room for `extra` more values (plus slack for a full vector store).
  void Reserve(std::size_t extra) {
    if (size_ + extra + 4 <= capacity_) return;
    const std::size_t capacity = std::max(2 * capacity_, size_ + extra + 4);
    std::unique_ptr<double[]> data(new double[capacity]);
    std::copy(begin(), end(), data.get());
    data_ = std::move(data);
    capacity_ = capacity;
  }
  void Push(double v) {
    Reserve(1);
    data_[size_++] = v;
  }
  void Append(const double* y, std::size_t n) {
    Reserve(n);
    std::copy(y, y + n, end());
    size_ += n;
  }
  void SetEnd(double* end) { size_ = static_cast<std::size_t>(end - data_.get()); }

 private:
  std::unique_ptr<double[]> data_;
  std::size_t size_ = 0, capacity_ = 0;
};

struct Window {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  std::uint64_t below = 0;  // y < lo
  Kept kept;                // lo <= y <= hi
};

// The shifted sums of one block, Σ(y − shift) and Σ(y − shift)², which the Monte Carlo's moments
// take in the same pass over the values (monte_carlo.cpp). Each is a plain floating-point sum of
// at most one block's terms (kBlock = 2048), in an order that depends on the kernel: relative
// error ≤ ~2048·2^-53 of Σ|y − shift| (resp. Σ(y − shift)²) per block, before the blocks'
// compensated total.
struct BlockSums {
  double shift = 0.0;
  double sum = 0.0, sum2 = 0.0;
};

// Counts and keeps one block's values y[0 … n) for both windows of an output (AVX2 where the
// kernel allows it and the CPU has it; both versions count and keep the same values, perhaps in
// another order, which Select does not see), and adds the block's shifted sums to `sums` if
// given.
void CountWindows(Window (&w)[2], const double* y, std::size_t n, VectorKernel kernel,
                  BlockSums* sums = nullptr);

// The 1-based ranks [low, high] of the probabilistically symmetric coverage interval with
// probability p among m values (JCGM 101 §7.7), clamped into [1, m].
void CoverageRanks(std::uint64_t m, double p, std::uint64_t* low, std::uint64_t* high);

// The k-th smallest (1-based) value, or nullopt when the window does not hold it.
std::optional<double> Select(Window& w, std::uint64_t k);

}  // namespace uphill::internal
