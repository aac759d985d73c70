// `uphill bench convert`: throughput of the batch conversion (L, H, D → θ, α, X) and of the Monte
// Carlo propagation on one core, each row with the accuracy it reached and its peak memory, and
// the same work in NumPy (tools/bench/numpy_convert.py) on the same numbers. What it measures and
// how: docs/bench.md; its latest results: docs/benchmarks.md.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "bench/options.hpp"

namespace uphill::bench {

struct ConvertBenchmarkOptions {
  CommonOptions common;
  std::uint64_t configurations = 10'000'000;
  std::uint64_t trials = 1'000'000;
  std::uint64_t seed = 1;
  int repeats = 3;
  std::string script;     // default: tools/bench/numpy_convert.py found upward
  std::string reference;  // default: tests/data/physics_reference.json found upward
  bool no_numpy = false;
};

void RunConvertBenchmark(const ConvertBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
