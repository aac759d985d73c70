// `uphill bench motion`: work–precision of the motion methods (src/motion) on three
// trajectories (oracle/motion_problems.hpp), against 50-digit references (src/oracle) and SciPy/NumPy (tools/bench/
// motion_peers.py), with a gnuplot figure of time against error. What it measures and how:
// docs/bench.md; its latest results: docs/benchmarks.md.
#pragma once

#include <ostream>
#include <string>

#include "bench/options.hpp"

namespace uphill::bench {

struct MotionBenchmarkOptions {
  CommonOptions common;
  std::string out = "bench-motion";  // folder of the work-precision figure
  std::string script;                // default: tools/bench/motion_peers.py found upward
  bool no_python = false;
  bool release_only = false;  // only the ReleaseTimes rows (no Motion rows, no peers)
};

void RunMotionBenchmark(const MotionBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
