#include "video_progress.hpp"

#include <algorithm>
#include <cstdio>

namespace uphill::cli {

VideoProgressDisplay::VideoProgressDisplay(const std::vector<std::string>& trials)
    : lines_(trials.size() + 1), start_(std::chrono::steady_clock::now()) {
  for (const std::string& t : trials) {
    videos_.push_back({t, {}, start_});
    label_width_ = std::max(label_width_, t.size());
  }
  for (std::size_t i = 0; i < videos_.size(); ++i) Update(videos_[i].last);
}

void VideoProgressDisplay::Update(const VideoProgress& p) {
  if (p.index >= videos_.size()) return;
  Video& v = videos_[p.index];
  const auto now = std::chrono::steady_clock::now();
  if (p.stage == VideoProgress::Stage::kTracking && v.last.stage != VideoProgress::Stage::kTracking) v.started = now;
  v.last = p;
  const auto seconds = [](auto d) { return std::chrono::duration<double>(d).count(); };
  std::string text;
  switch (p.stage) {
    case VideoProgress::Stage::kQueued: text = "waiting"; break;
    case VideoProgress::Stage::kHashing: text = "hashing the video"; break;
    case VideoProgress::Stage::kTracking: text = FrameProgressText(p.frames_done, p.frames_total, seconds(now - v.started), 30); break;
    case VideoProgress::Stage::kAnalysing: text = "analysing the track"; break;
    case VideoProgress::Stage::kCached: text = "from the cache"; break;
    case VideoProgress::Stage::kDone: text = "done"; break;
    case VideoProgress::Stage::kFailed: text = "failed (see below)"; break;
  }
  std::string label = v.label;
  label.resize(label_width_, ' ');
  lines_.Set(p.index, label + "  " + text);
  std::size_t finished = 0;
  long frames = 0;
  for (const Video& w : videos_) {
    const auto s = w.last.stage;
    if (s == VideoProgress::Stage::kCached || s == VideoProgress::Stage::kDone || s == VideoProgress::Stage::kFailed) ++finished;
    frames += w.last.frames_done;
  }
  const double elapsed = seconds(now - start_);
  char total[128];
  std::snprintf(total, sizeof total, "] %zu/%zu videos, %ld frames, %.0f frames/s, %.1f s", finished, videos_.size(),
                frames, frames / std::max(elapsed, 1e-9), elapsed);
  const int width = 30, filled = static_cast<int>(width * static_cast<double>(finished) / std::max<std::size_t>(1, videos_.size()));
  std::string label_total = "total";
  label_total.resize(label_width_, ' ');
  lines_.Set(videos_.size(), label_total + "  [" + std::string(filled, '#') + std::string(width - filled, '.') + total);
  lines_.Draw(p.stage != VideoProgress::Stage::kTracking);
}

void VideoProgressDisplay::Finish() { lines_.Finish(); }

}  // namespace uphill::cli
