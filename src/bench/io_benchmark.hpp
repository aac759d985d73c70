// `uphill bench io`: the program end to end on large CSV files, as a user meets it - `uphill fit
// --xy` and `uphill convert --batch` run as their own processes (start, reading, work, output) -
// against a NumPy script doing the same in its own process (tools/bench/io_peers.py: interpreter
// start, np.loadtxt, the fit or conversion, optionally np.savetxt), on the very same files, for
// N = 10^4, 10^6, 10^7 rows; each row with the accuracy reached and the peak resident memory
// against the file's size. Then bad input at scale: one bad cell near the end of the largest file,
// the file cut off mid-row, a 2 GB line without a line end. What it measures and how:
// docs/bench.md; its latest results: docs/benchmarks.md.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "bench/options.hpp"

namespace uphill::bench {

struct IoBenchmarkOptions {
  CommonOptions common;
  std::vector<std::uint64_t> sizes = {10'000, 1'000'000, 10'000'000};
  std::uint64_t seed = 1;
  int repeats = 3;            // runs per row at N ≤ 10^6 (the best counts); one at larger N
  std::string folder;         // where the files go (default: a temporary folder, removed after)
  std::string script;         // default: tools/bench/io_peers.py found upward
  bool no_peers = false;
  bool no_bad_input = false;  // skip the bad-input cases
  std::uint64_t long_line_bytes = std::uint64_t{2} << 30;  // the line without a line end
};

void RunIoBenchmark(const IoBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
