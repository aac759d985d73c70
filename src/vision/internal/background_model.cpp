#include "background_model.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace uphill::internal {

BackgroundModel::BackgroundModel(const cv::Mat& band, Transfer transfer)
    : table_(LinearTable(transfer)), band_(band.clone()) {
  box_ = cv::boundingRect(band_);
  background_ = cv::Mat::zeros(band.size(), CV_32FC3);
  count_ = cv::Mat::zeros(band.size(), CV_8U);
  // About 1000 probes spread evenly over the band (a fixed lattice: reproducible).
  const double area = std::max(1, cv::countNonZero(band_));
  const int step = std::max(1, static_cast<int>(std::sqrt(area / 1000.0)));
  for (int y = box_.y + step / 2; y < box_.y + box_.height; y += step)
    for (int x = box_.x + ((y / step) % 2) * step / 2; x < box_.x + box_.width; x += step)
      if (band_.at<std::uint8_t>(y, x)) probes_.emplace_back(x, y);
}

void BackgroundModel::Forget() {
  background_.setTo(cv::Scalar::all(0));
  count_.setTo(cv::Scalar::all(0));
  gain_ = 1;
  residual_ = -1;
}

bool BackgroundModel::Measure(const cv::Mat& bgr, const cv::Rect& exclude) {
  std::vector<float> ratios, residuals;
  ratios.reserve(probes_.size());
  residuals.reserve(probes_.size());
  for (const cv::Point& p : probes_) {
    if (exclude.contains(p) || !count_.at<std::uint8_t>(p)) continue;
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(p.y) + 3 * p.x;
    const cv::Vec3f& b = background_.at<cv::Vec3f>(p);
    const float lum_b = b[0] + b[1] + b[2];
    if (lum_b < 0.02f) continue;  // too dark to measure a ratio
    const float lum = table_[px[0]] + table_[px[1]] + table_[px[2]];
    ratios.push_back(lum / lum_b);
  }
  if (ratios.size() < 50) {
    gain_ = 1;
    residual_ = -1;
    return false;
  }
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  gain_ = ratios[ratios.size() / 2];
  for (const cv::Point& p : probes_) {
    if (exclude.contains(p) || !count_.at<std::uint8_t>(p)) continue;
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(p.y) + 3 * p.x;
    const cv::Vec3f& b = background_.at<cv::Vec3f>(p);
    const float lum_b = b[0] + b[1] + b[2];
    if (lum_b < 0.02f) continue;
    const float lum = table_[px[0]] + table_[px[1]] + table_[px[2]];
    residuals.push_back(std::abs(lum / static_cast<float>(gain_) - lum_b) / lum_b);
  }
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  residual_ = residuals[residuals.size() / 2];
  return true;
}

void BackgroundModel::Learn(const cv::Mat& bgr, const cv::Rect& exclude) {
  const float inv_gain = static_cast<float>(1.0 / gain_);
  const float clamp = static_cast<float>(std::max(4 * noise_, 0.01));
  double abs_sum = 0;
  long abs_count = 0;
  for (int y = box_.y; y < box_.y + box_.height; ++y) {
    const std::uint8_t* mask = band_.ptr<std::uint8_t>(y);
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(y);
    cv::Vec3f* b = background_.ptr<cv::Vec3f>(y);
    std::uint8_t* n = count_.ptr<std::uint8_t>(y);
    const bool row_excluded = y >= exclude.y && y < exclude.y + exclude.height;
    for (int x = box_.x; x < box_.x + box_.width; ++x) {
      if (!mask[x] || (row_excluded && x >= exclude.x && x < exclude.x + exclude.width)) continue;
      const std::uint8_t* p = px + 3 * x;
      const cv::Vec3f value(table_[p[0]] * inv_gain, table_[p[1]] * inv_gain, table_[p[2]] * inv_gain);
      if (n[x] == 0) {
        b[x] = value;
        n[x] = 1;
        continue;
      }
      const float eta = 1.0f / static_cast<float>(std::min<int>(n[x] + 1, kAveraged));
      cv::Vec3f step = value - b[x];
      if (n[x] >= 3) {
        abs_sum += std::abs(step[1]);
        ++abs_count;
        for (int c = 0; c < 3; ++c) step[c] = std::clamp(step[c], -clamp, clamp);
      }
      b[x] += eta * step;
      if (n[x] < 255) ++n[x];
    }
  }
  // Mean |I/g − B| ≈ 0.8 σ for Gaussian noise.
  if (abs_count > 100) noise_ = 0.8 * noise_ + 0.2 * (abs_sum / abs_count / 0.8);
}

}  // namespace uphill::internal
