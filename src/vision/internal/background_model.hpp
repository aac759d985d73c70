// The clip's background where the body can be: the camera and the apparatus stand still and only
// the body moves, so each pixel of the band the body sweeps shows, in the frames where the body
// is elsewhere, the same table, rail or wall. Learnt online in one pass (no second decode): each
// frame, the band's pixels outside the region the body occupies (its smeared silhouette widened
// by a radius, and its shadow below it) update a per-pixel estimate in linear light, normalised
// by the frame's exposure gain.
//
// Estimate: B ← B + η·clamp(I/g − B, ±k) with η = 1/n for the first `kAveraged` looks (the mean
// of those frames) and 1/kAveraged after (an exponential memory of about that many frames); the
// clamp (k = 4 noise levels, once a pixel has been seen 3 times) keeps a body the tracker missed
// from being learnt into the background in one frame. A pixel never seen without the body (where
// it rested from the first frame) stays unknown: Known() says so and the tracker falls back to a
// per-ray background.
//
// Gain g (Gain()): the median over ~1000 fixed pixels of the band, known and outside the body's
// region, of the ratio of this frame's luminance to the background's: lamp flicker and
// auto-exposure scale the whole picture, so that B·g is this frame's background.
//
// Scene change (SceneResidual()): the median over the same pixels of |I/g − B| relative to the
// background's level, after the gain: a few per cent on a steady scene (noise, compression); a
// camera that moved shifts every edge of the table and the rails, and it jumps.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "linear_light.hpp"

namespace uphill::internal {

class BackgroundModel {
 public:
  static constexpr int kAveraged = 8;

  // band: CV_8U mask (non-zero: pixels the body can cover), the frame's size; kept, its pixels
  // shared (cv::Mat), so not to be changed afterwards.
  BackgroundModel(cv::Mat band, Transfer transfer);

  // This frame's gain and scene residual (before Learn), `exclude` the body's region (may be
  // empty: nothing excluded). Returns false when too few known pixels (gain 1, residual unknown).
  bool Measure(const cv::Mat& bgr, const cv::Rect& exclude);
  double Gain() const { return gain_; }
  double SceneResidual() const { return residual_; }

  // Learns the band's pixels of `bgr` outside `exclude` (gain from the last Measure), only those
  // inside `within` unless it is empty (the noise level, which sets the clamp, is then kept).
  void Learn(const cv::Mat& bgr, const cv::Rect& exclude, const cv::Rect& within = cv::Rect());

  // Whether every pixel of `rect` (clipped to the frame) has been seen; the background there
  // (linear light, gain 1), bilinear.
  bool Known(double x, double y) const {
    const int i = static_cast<int>(x) - box_.x, j = static_cast<int>(y) - box_.y;
    return i >= 0 && j >= 0 && i + 1 < count_.cols && j + 1 < count_.rows && count_.at<std::uint8_t>(j, i) &&
           count_.at<std::uint8_t>(j, i + 1) && count_.at<std::uint8_t>(j + 1, i) && count_.at<std::uint8_t>(j + 1, i + 1);
  }
  // Only where Known(x, y).
  cv::Vec3f At(double x, double y) const { return SampleFloat(background_, x - box_.x, y - box_.y); }
  // The band's bounding box, frame pixels: all a later look at the background needs of a frame.
  const cv::Rect& box() const { return box_; }
  bool InBand(double x, double y) const {
    return band_.at<std::uint8_t>(static_cast<int>(y), static_cast<int>(x)) != 0;
  }

  const std::array<float, 256>& table() const { return table_; }
  void Forget();  // after a scene change: learn again from scratch

 private:
  std::array<float, 256> table_;
  cv::Rect box_;                    // bounding box of the band
  cv::Mat band_;                    // CV_8U, frame size
  // The band's runs of pixels, row by row (frame columns [begin, end)): Learn visits only those.
  struct Run {
    int y, begin, end;
  };
  std::vector<Run> runs_;
  cv::Mat background_;              // CV_32FC3 over box_, defined where count_ > 0
  cv::Mat count_;                   // CV_8U over box_, looks so far (saturating)
  std::vector<cv::Point> probes_;   // fixed pixels of the band for the gain
  std::vector<float> probe_luminance_;  // the background's B + G + R at each probe, 0 if unknown
  void UpdateProbes();
  double gain_ = 1, residual_ = -1;
  double noise_ = 0.01;             // linear units, running estimate of |I/g − B|
};

}  // namespace uphill::internal
