// Pixels back to linear light. A camera records the light a pixel integrates (so a motion-blurred
// or anti-aliased edge is a linear blend of body and background), then encodes it with a transfer
// curve; blends are only linear after decoding. Edges located on the encoded values move toward
// the darker side by a fraction of their width (0.3 px on a sharp edge between a dark ball and
// the lit wood, more on a blurred one), so the tracker decodes first.
#pragma once

#include <array>
#include <opencv2/core.hpp>

namespace uphill::internal {

enum class Transfer { kSrgb, kLinear };

// Table of the linear value (0..1) of each 8-bit code.
std::array<float, 256> LinearTable(Transfer transfer);

// Bilinear sample of an 8-bit BGR image in linear light (channels B, G, R) at raw pixel (x, y),
// which must lie at least one pixel inside the image.
inline cv::Vec3f SampleLinear(const cv::Mat& bgr, const std::array<float, 256>& table, double x, double y) {
  const int i = static_cast<int>(x), j = static_cast<int>(y);
  const float fx = static_cast<float>(x - i), fy = static_cast<float>(y - j);
  const std::uint8_t* r0 = bgr.ptr<std::uint8_t>(j) + 3 * i;
  const std::uint8_t* r1 = bgr.ptr<std::uint8_t>(j + 1) + 3 * i;
  cv::Vec3f out;
  for (int c = 0; c < 3; ++c) {
    const float top = table[r0[c]] + fx * (table[r0[c + 3]] - table[r0[c]]);
    const float bottom = table[r1[c]] + fx * (table[r1[c + 3]] - table[r1[c]]);
    out[c] = top + fy * (bottom - top);
  }
  return out;
}

// Bilinear sample of a CV_32FC3 image at (x, y) (at least one pixel inside).
inline cv::Vec3f SampleFloat(const cv::Mat& image, double x, double y) {
  const int i = static_cast<int>(x), j = static_cast<int>(y);
  const float fx = static_cast<float>(x - i), fy = static_cast<float>(y - j);
  const cv::Vec3f* r0 = image.ptr<cv::Vec3f>(j) + i;
  const cv::Vec3f* r1 = image.ptr<cv::Vec3f>(j + 1) + i;
  const cv::Vec3f top = r0[0] + fx * (r0[1] - r0[0]);
  const cv::Vec3f bottom = r1[0] + fx * (r1[1] - r1[0]);
  return top + fy * (bottom - top);
}

}  // namespace uphill::internal
