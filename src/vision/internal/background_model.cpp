#include "background_model.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace uphill::internal {

BackgroundModel::BackgroundModel(cv::Mat band, Transfer transfer)
    : table_(LinearTable(transfer)), band_(std::move(band)) {
  box_ = cv::boundingRect(band_);
  // Not cleared: a pixel's background is read only once it has been seen (count_), and memory
  // never written is then usually never faulted in (a block this large comes from mmap; at
  // 1080p the band's box holds megabytes, most of it outside the band, and clearing it would
  // dominate the tracker's set-up).
  background_.create(box_.size(), CV_32FC3);
  count_ = cv::Mat::zeros(box_.size(), CV_8U);
  for (int y = box_.y; y < box_.y + box_.height; ++y) {
    const std::uint8_t* mask = band_.ptr<std::uint8_t>(y);
    for (int x = box_.x; x < box_.x + box_.width;) {
      if (!mask[x]) {
        ++x;
        continue;
      }
      const int begin = x;
      while (x < box_.x + box_.width && mask[x]) ++x;
      runs_.push_back({y, begin, x});
    }
  }
  // About 1000 probes spread evenly over the band (a fixed lattice: reproducible).
  const double area = std::max(1, cv::countNonZero(band_));
  const int step = std::max(1, static_cast<int>(std::sqrt(area / 1000.0)));
  for (int y = box_.y + step / 2; y < box_.y + box_.height; y += step)
    for (int x = box_.x + ((y / step) % 2) * step / 2; x < box_.x + box_.width; x += step)
      if (band_.at<std::uint8_t>(y, x)) probes_.emplace_back(x, y);
  probe_luminance_.assign(probes_.size(), 0.0f);
}

void BackgroundModel::UpdateProbes() {
  for (size_t k = 0; k < probes_.size(); ++k) {
    const cv::Point p = probes_[k] - box_.tl();
    const cv::Vec3f& b = background_.at<cv::Vec3f>(p);
    probe_luminance_[k] = count_.at<std::uint8_t>(p) ? b[0] + b[1] + b[2] : 0.0f;
  }
}

void BackgroundModel::Forget() {
  count_.setTo(cv::Scalar::all(0));
  std::fill(probe_luminance_.begin(), probe_luminance_.end(), 0.0f);
  gain_ = 1;
  residual_ = -1;
}

bool BackgroundModel::Measure(const cv::Mat& bgr, const cv::Rect& exclude) {
  // (this frame's luminance, the background's) at each usable probe.
  std::vector<std::pair<float, float>> looks;
  looks.reserve(probes_.size());
  for (size_t k = 0; k < probes_.size(); ++k) {
    const cv::Point& p = probes_[k];
    const float lum_b = probe_luminance_[k];
    if (lum_b < 0.02f || exclude.contains(p)) continue;  // unknown, or too dark to measure a ratio
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(p.y) + 3 * p.x;
    looks.emplace_back(table_[px[0]] + table_[px[1]] + table_[px[2]], lum_b);
  }
  if (looks.size() < 50) {
    gain_ = 1;
    residual_ = -1;
    return false;
  }
  std::vector<float> values(looks.size());
  for (size_t k = 0; k < looks.size(); ++k) values[k] = looks[k].first / looks[k].second;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  gain_ = values[values.size() / 2];
  for (size_t k = 0; k < looks.size(); ++k)
    values[k] = std::abs(looks[k].first / static_cast<float>(gain_) - looks[k].second) / looks[k].second;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  residual_ = values[values.size() / 2];
  return true;
}

void BackgroundModel::Learn(const cv::Mat& bgr, const cv::Rect& exclude, const cv::Rect& within) {
  const float inv_gain = static_cast<float>(1.0 / gain_);
  const float clamp = static_cast<float>(std::max(4 * noise_, 0.01));
  // η = 1/min(n + 1, kAveraged) by the count n so far.
  static const std::array<float, 256> eta = [] {
    std::array<float, 256> e;
    for (int n = 0; n < 256; ++n) e[n] = 1.0f / static_cast<float>(std::min(n + 1, kAveraged));
    return e;
  }();
  double abs_sum = 0;
  long abs_count = 0;
  const auto learn = [&](int y, int begin, int end) {
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(y) + 3 * begin;
    cv::Vec3f* b = background_.ptr<cv::Vec3f>(y - box_.y) + (begin - box_.x);
    std::uint8_t* n = count_.ptr<std::uint8_t>(y - box_.y) + (begin - box_.x);
    float row_abs = 0;
    int row_count = 0;
    for (int k = 0; k < end - begin; ++k, px += 3) {
      const cv::Vec3f value(table_[px[0]] * inv_gain, table_[px[1]] * inv_gain, table_[px[2]] * inv_gain);
      if (n[k] == 0) {
        b[k] = value;
        n[k] = 1;
        continue;
      }
      cv::Vec3f step = value - b[k];
      if (n[k] >= 3) {
        row_abs += std::abs(step[1]);
        ++row_count;
        for (int c = 0; c < 3; ++c) step[c] = std::clamp(step[c], -clamp, clamp);
      }
      b[k] += eta[n[k]] * step;
      if (n[k] < 255) ++n[k];
    }
    abs_sum += row_abs;
    abs_count += row_count;
  };
  const int ex0 = exclude.x, ex1 = exclude.x + exclude.width;
  for (Run run : runs_) {
    if (!within.empty()) {
      if (run.y < within.y || run.y >= within.y + within.height) continue;
      run.begin = std::max(run.begin, within.x), run.end = std::min(run.end, within.x + within.width);
      if (run.begin >= run.end) continue;
    }
    if (exclude.empty() || run.y < exclude.y || run.y >= exclude.y + exclude.height || run.end <= ex0 || run.begin >= ex1) {
      learn(run.y, run.begin, run.end);
      continue;
    }
    if (run.begin < ex0) learn(run.y, run.begin, ex0);
    if (run.end > ex1) learn(run.y, ex1, run.end);
  }
  UpdateProbes();
  // Mean |I/g − B| ≈ 0.8 σ for Gaussian noise; from the whole band only (near the body a rail's
  // reflection or the shadow's edge would take part in it).
  if (within.empty() && abs_count > 100) noise_ = 0.8 * noise_ + 0.2 * (abs_sum / abs_count / 0.8);
}

}  // namespace uphill::internal
