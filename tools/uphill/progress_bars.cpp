#include "progress_bars.hpp"

#include <algorithm>
#include <cstdio>

namespace uphill::cli {

std::string FrameProgressText(int done, long total, double elapsed, int width) {
  const double rate = done / std::max(elapsed, 1e-9);
  char tail[96];
  if (total > 0) {
    const int filled = static_cast<int>(width * std::min(1.0, static_cast<double>(done) / static_cast<double>(total)));
    std::snprintf(tail, sizeof tail, "] %d/%ld frames, %.0f frames/s", done, total, rate);
    return "[" + std::string(filled, '#') + std::string(width - filled, '.') + tail;
  }
  std::snprintf(tail, sizeof tail, "%d frames, %.0f frames/s", done, rate);
  return tail;
}

ProgressLines::ProgressLines(std::size_t count) : lines_(count) {}

void ProgressLines::Set(std::size_t line, std::string text) {
  if (line < lines_.size()) lines_[line] = std::move(text);
}

void ProgressLines::Draw(bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  std::string out;
  if (drawn_ && lines_.size() > 1) out += "\033[" + std::to_string(lines_.size() - 1) + "A";
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    out += "\r\033[2K" + lines_[i];
    if (i + 1 < lines_.size()) out += "\n";
  }
  std::fputs(out.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLines::Finish() {
  Draw(true);
  std::fputs("\n", stderr);
  std::fflush(stderr);
}

}  // namespace uphill::cli
