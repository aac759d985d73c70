// `uphill bench python`: what a call of the Python module costs beside the C++ kernel it runs,
// and beside NumPy in the same Python process (tools/bench/python_module.py), on 10^6 elements:
// the batch conversion (uphill.convert_apparatus, into preallocated arrays and allocating) and
// York's fit (uphill.fit_york), each row with its accuracy and peak memory. What it measures and
// how: docs/bench.md; its latest results: docs/benchmarks.md.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "bench/options.hpp"

namespace uphill::bench {

struct PythonBenchmarkOptions {
  CommonOptions common;
  std::uint64_t elements = 1'000'000;
  std::uint64_t seed = 1;
  int repeats = 5;
  std::string script;      // default: tools/bench/python_module.py found upward
  std::string module_dir;  // default: this build's python/ folder, else Python's own path
};

// Prints the table to `out` as it is measured and records it (results_document.hpp). Throws
// InputError for invalid options, std::runtime_error when the Python side fails.
void RunPythonBenchmark(const PythonBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
