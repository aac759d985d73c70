// `uphill bench track`: speed and accuracy of the ball tracker (src/vision) on synthetic clips
// with exact ground truth, against decoding alone and OpenCV's trackers (tools/bench/
// track_peers.py). What it measures and how: docs/bench.md; its latest results:
// docs/benchmarks.md.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "bench/options.hpp"

namespace uphill::bench {

struct TrackBenchmarkOptions {
  CommonOptions common;
  std::string cache = "/tmp/uphill-bench-track";  // rendered clips, reused between runs
  std::string script;                             // default: tools/bench/track_peers.py found upward
  bool no_python = false;
  bool fresh = false;  // render the clips again
  // The robustness table on the ray-traced footage (bench/track_matrix.hpp).
  bool no_matrix = false, only_matrix = false;
  std::vector<std::string> conditions;  // empty: the whole matrix
  std::string footage_cache;            // "": vision::FootageCacheRoot()
  std::string positions;                // "": no per-frame files (TrackMatrixOptions::positions)
  // --random N: only the random scenes (bench/track_random.hpp), nothing recorded in the doc.
  int random = 0;
  std::optional<std::uint64_t> seed;    // unset: a new seed each run (printed)
  std::string random_cache = "/tmp/uphill-bench-random";
  std::string json;                     // --json FILE: the random scenes' results
  std::vector<std::string> draw_ids;    // --draw ID...: only these of the N draws
  std::optional<double> min_quality;    // --min-quality: the tracker's TrackerOptions::min_report_quality
};

void RunTrackBenchmark(const TrackBenchmarkOptions& options, std::ostream& out);

}  // namespace uphill::bench
