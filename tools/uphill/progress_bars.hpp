// Progress bars on stderr, for the commands that track videos: one bar (`uphill track`) or one
// line per video and a total below them (`uphill report` / `uphill fit` of an experiment with
// recordings), redrawn in place. Only used when stderr is a terminal (the caller checks).
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace uphill::cli {

// "[#######.....] 120/300 frames, 45 frames/s" (total 0: "120 frames, 45 frames/s").
std::string FrameProgressText(int done, long total, double elapsed_seconds, int width = 40);

// Lines of text redrawn in place (ANSI cursor-up), at most every 0.1 s unless forced.
class ProgressLines {
 public:
  explicit ProgressLines(std::size_t count);
  void Set(std::size_t line, std::string text);
  void Draw(bool force = false);
  // Draws a last time and leaves the cursor below the lines.
  void Finish();

 private:
  std::vector<std::string> lines_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace uphill::cli
