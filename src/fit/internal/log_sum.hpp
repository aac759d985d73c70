// Internal to the fit layer: Σ ln v_i of positive doubles without a logarithm per value (the
// information criteria need Σ ln σ_i², which per row would cost more than the rest of a fit).
// v = mantissa·2^exponent with the mantissa in [1, 2): Σ ln v = ln 2·Σ exponent + ln Π mantissa,
// the product taken in four interleaved partial products of at most 257 values each (< 2^257, no
// overflow; independent, so the multiplications pipeline) and their logarithms added in long
// double. A subnormal v (exponent field 0) takes the logarithm of that chunk's values one by one.
// Accuracy: a few ulp of long double per chunk.
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

namespace uphill::internal {

class LogSum {
 public:
  // Adds ln v[j] for j < m ≤ 1024; every v[j] > 0 and finite.
  void Add(const double* v, std::size_t m) {
    std::int64_t exponents = 0;
    double m0 = 1.0, m1 = 1.0, m2 = 1.0, m3 = 1.0;
    bool subnormal = false;
    const auto take = [&](double value, double& mantissas) {
      const std::uint64_t bits = std::bit_cast<std::uint64_t>(value);
      const std::int64_t exponent = static_cast<std::int64_t>(bits >> 52);  // v > 0: no sign bit
      exponents += exponent - 1023;
      subnormal |= exponent == 0;
      mantissas *= std::bit_cast<double>((bits & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull);
    };
    std::size_t j = 0;
    for (; j + 4 <= m; j += 4) take(v[j], m0), take(v[j + 1], m1), take(v[j + 2], m2), take(v[j + 3], m3);
    for (; j < m; ++j) take(v[j], m0);
    if (!subnormal) {
      sum_ += static_cast<long double>(exponents) * std::numbers::ln2_v<long double> +
              std::log(static_cast<long double>(m0) * m1) + std::log(static_cast<long double>(m2) * m3);
    } else {
      for (std::size_t j = 0; j < m; ++j) sum_ += std::log(static_cast<long double>(v[j]));
    }
  }
  long double value() const { return sum_; }

 private:
  long double sum_ = 0;
};

}  // namespace uphill::internal
