// `uphill bench fit`: time, accuracy and peak memory of every line fit (OLS, WLS, York, robust)
// and of the friction fit, against extended-precision references (src/oracle) and the
// NumPy/SciPy peers (tools/bench/fit_peers.py) on the very same doubles. What it measures and how:
// docs/bench.md; its latest results: docs/benchmarks.md.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "bench/options.hpp"

namespace uphill::bench {

struct FitBenchmarkOptions {
  CommonOptions common;
  std::vector<std::uint64_t> sizes = {100, 10'000, 1'000'000};
  std::vector<std::uint64_t> friction_sizes = {100, 10'000};
  std::uint64_t offset_rows = 10'000;  // the X ≈ 1e9 case (0: skip)
  std::uint64_t seed = 1;
  int repeats = 3;
  std::string script;  // default: tools/bench/fit_peers.py found upward
  bool no_peers = false;
  bool no_odr = false;
  bool no_rlm = false;
};

// Prints the tables to `out` as they are measured and records them (results_document.hpp).
// Throws InputError for invalid options.
void RunFitBenchmark(const FitBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
