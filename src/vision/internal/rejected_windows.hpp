// Where a search for a lost body found none, and the pixels it looked at. Private to src/vision/.
//
// The same pixels give the same verdict: a candidate the model fitted and rejected need not be
// fitted again while its window of the frame is unchanged. It matters after the body has left
// the picture (rolled off the rails, taken out by hand): the search along the whole path then
// runs on every remaining frame, and it keeps proposing the same places, above all the one where
// the body rested, whose background was never seen, at the cost of a model fit each. A body that
// enters such a window changes its pixels and is fitted at once, so nothing visible is missed.
//
// Unchanged: the window's pixels against those of the frame where the candidate was rejected
// (not the previous frame, so that a slow creep adds up). With d the sum over B, G, R of the
// absolute 8-bit difference per pixel and m its median over the window, the window is unchanged
// when m <= kMaxMedianChange (a global change, lamp flicker or auto-exposure, or heavy noise:
// treated as changed, fitted again) and at most kMaxChangedShare of its pixels have
// d > max(kMinChange, kNoiseFactor · m) (sensor and compression noise stay under that; a body
// entering changes a patch of its disc).
#pragma once

#include <deque>
#include <opencv2/core.hpp>

namespace uphill::internal {

class RejectedWindows {
 public:
  static constexpr int kMaxWindows = 16;  // every place the search proposes (Candidates)
  static constexpr double kMaxMedianChange = 12;   // levels, summed over the channels
  static constexpr double kMinChange = 24;         // levels, summed over the channels
  static constexpr double kNoiseFactor = 3;
  static constexpr double kMaxChangedShare = 0.01;

  // Whether `box` lies within a remembered window whose pixels in `bgr` (8-bit BGR, the frame's
  // size) are unchanged.
  bool Unchanged(const cv::Mat& bgr, const cv::Rect& box) const;
  // Remembers `box` of `bgr` as fitted and rejected (the oldest window goes beyond kMaxWindows;
  // a window over the same box is replaced).
  void Remember(const cv::Mat& bgr, const cv::Rect& box);
  void Clear() { windows_.clear(); }

  // The comparison alone, for two 8-bit BGR images of one size.
  static bool Same(const cv::Mat& now, const cv::Mat& then);

 private:
  struct Window {
    cv::Rect box;
    cv::Mat pixels;
  };
  std::deque<Window> windows_;
};

}  // namespace uphill::internal
