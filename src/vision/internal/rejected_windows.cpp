#include "rejected_windows.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace uphill::internal {

bool RejectedWindows::Same(const cv::Mat& now, const cv::Mat& then) {
  CV_Assert(now.type() == CV_8UC3 && then.type() == CV_8UC3 && now.size() == then.size());
  std::vector<int> d;
  d.reserve(now.total());
  for (int y = 0; y < now.rows; ++y) {
    const std::uint8_t* a = now.ptr<std::uint8_t>(y);
    const std::uint8_t* b = then.ptr<std::uint8_t>(y);
    for (int x = 0; x < 3 * now.cols; x += 3)
      d.push_back(std::abs(a[x] - b[x]) + std::abs(a[x + 1] - b[x + 1]) + std::abs(a[x + 2] - b[x + 2]));
  }
  if (d.empty()) return false;
  std::vector<int> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  if (median > kMaxMedianChange) return false;
  const double threshold = std::max(kMinChange, kNoiseFactor * median);
  const auto changed = std::count_if(d.begin(), d.end(), [&](int v) { return v > threshold; });
  return static_cast<double>(changed) <= kMaxChangedShare * static_cast<double>(d.size());
}

bool RejectedWindows::Unchanged(const cv::Mat& bgr, const cv::Rect& box) const {
  for (const Window& w : windows_)
    if ((box & w.box) == box) return Same(bgr(w.box), w.pixels);
  return false;
}

void RejectedWindows::Remember(const cv::Mat& bgr, const cv::Rect& box) {
  if (box.empty()) return;
  std::erase_if(windows_, [&](const Window& w) { return w.box == box; });
  if (static_cast<int>(windows_.size()) >= kMaxWindows) windows_.pop_front();
  windows_.push_back({box, bgr(box).clone()});
}

}  // namespace uphill::internal
