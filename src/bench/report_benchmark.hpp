// `uphill bench report`: the fit report of an experiment whose trials are videos:
// 20 trial videos of 1080p, 10 s each (rendered once with exact ground truth into a cache folder
// outside the repository), reported by the `uphill report` program as a user runs it, against the
// time to decode all the videos alone, every core used; then a second report of the unchanged
// folder (the video cache). What it measures and how: docs/bench.md; results: docs/benchmarks.md.
#pragma once

#include <ostream>
#include <string>

#include "bench/options.hpp"

namespace uphill::bench {

struct ReportBenchmarkOptions {
  CommonOptions common;
  std::string cache = "/tmp/uphill-bench-report";  // the rendered experiment, reused between runs
  int videos = 20;
  int width = 1920, height = 1080;
  double seconds = 10;
  bool fresh = false;  // render the videos again
  unsigned jobs = 0;   // 0: every core
  int rounds = 2;      // each run's best of this many
};

// Throws InputError (naming the flag) for videos outside 2..200, rounds outside 1..20, seconds
// outside 3..120 or a size outside 320x180..4096x4096.
void RunReportBenchmark(const ReportBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
