// The progress of `uphill report` / `uphill fit` while an experiment's videos are tracked, on a
// terminal (progress_bars.hpp draws it). Only in uphill-vision, which links app/video_trials.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "app/video_trials.hpp"
#include "progress_bars.hpp"

namespace uphill::cli {

// The lines of `uphill report` / `uphill fit` while an experiment's videos are tracked
// (app/video_trials.hpp): one per video ("t3  [#####.....] 120/300 frames, 45 frames/s", "from
// the cache", "failed") and the total below them. Call it from the progress callback.
class VideoProgressDisplay {
 public:
  explicit VideoProgressDisplay(const std::vector<std::string>& trials);
  void Update(const VideoProgress& progress);
  void Finish();

 private:
  struct Video {
    std::string label;
    VideoProgress last;
    std::chrono::steady_clock::time_point started;
  };
  std::vector<Video> videos_;
  ProgressLines lines_;
  std::chrono::steady_clock::time_point start_;
  std::size_t label_width_ = 0;
};

}  // namespace uphill::cli
