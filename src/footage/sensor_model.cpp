#include "footage/sensor_model.hpp"

#include <Random123/boxmuller.hpp>
#include <Random123/philox.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace uphill {

double LightModel::Gain(double t) const {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  return (1 + flicker_depth * std::cos(kTwoPi * flicker_hz * t + flicker_phase)) *
         (1 + drift_depth * std::sin(kTwoPi * t / drift_period + drift_phase));
}

double LightModel::Integral(double a, double b) const {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  double flicker = b - a;
  if (flicker_depth != 0) {
    const double w = kTwoPi * flicker_hz;
    flicker += flicker_depth / w * (std::sin(w * b + flicker_phase) - std::sin(w * a + flicker_phase));
  }
  const double drift = 1 + drift_depth * std::sin(kTwoPi * (a + b) / 2 / drift_period + drift_phase);
  return flicker * drift;
}

double SrgbEncode(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
}

double SrgbDecode(double e) {
  e = std::clamp(e, 0.0, 1.0);
  return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

cv::Mat SensorModel::ToFrame8(const cv::Mat& linear, std::uint64_t frame) const {
  CV_Assert(linear.type() == CV_32FC3 && linear.isContinuous());
  // Encoding through a table of 2^16 + 1 steps of the clipped signal: the 8-bit rounding, not
  // the table, sets the precision (a step is < 0.02 of an 8-bit level at the darkest level).
  static const std::vector<std::uint8_t> kTable = [] {
    std::vector<std::uint8_t> t(65537);
    for (size_t i = 0; i < t.size(); ++i)
      t[i] = static_cast<std::uint8_t>(std::lround(255 * SrgbEncode(static_cast<double>(i) / 65536)));
    return t;
  }();
  cv::Mat out(linear.size(), CV_8UC3);
  const float* in = linear.ptr<float>();
  std::uint8_t* o = out.ptr<std::uint8_t>();
  const size_t pixels = linear.total();
  using Philox = r123::Philox4x32;
  Philox philox;
  const Philox::key_type key = {{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}};
  const double read2 = read_noise * read_noise;
  for (size_t p = 0; p < pixels; ++p) {
    double deviate[4] = {0, 0, 0, 0};
    if (noise) {
      const Philox::ctr_type counter = {{static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(p >> 32),
                                         static_cast<std::uint32_t>(frame), static_cast<std::uint32_t>(frame >> 32)}};
      const Philox::ctr_type r = philox(counter, key);
      const r123::float2 n01 = r123::boxmuller(r.v[0], r.v[1]);
      const r123::float2 n23 = r123::boxmuller(r.v[2], r.v[3]);
      deviate[0] = n01.x, deviate[1] = n01.y, deviate[2] = n23.x;
    }
    for (int c = 0; c < 3; ++c) {
      double s = std::max(0.0, static_cast<double>(in[3 * p + c]));
      if (noise) {
        const double electrons = s * full_well;
        s = (electrons + std::sqrt(electrons + read2) * deviate[c]) / full_well;
      }
      const double clipped = std::clamp(s, 0.0, 1.0);
      o[3 * p + c] = kTable[static_cast<size_t>(std::lround(clipped * 65536))];
    }
  }
  return out;
}

}  // namespace uphill
