// Internal to src/vision: the frames of a track in which the ball was found, and the small
// statistics the event detection (track_events.hpp) and the model fit (track_model_fit.hpp) share.
#pragma once

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "model/number_text.hpp"

namespace uphill::internal {

// The frames found, in time order.
struct Series {
  std::vector<double> t, x, z;
  std::vector<double> u, v;  // raw pixels of the centre (the tracker's systematic error is in pixels)
  std::vector<double> time_u;  // s: each time's uncertainty shared by all frames (Track::row_delay_u)
  std::vector<double> outline;  // m: TrackFrame::u_outline_px at the body's scale (0: not stated)
  std::vector<int> rows;
  int size() const { return static_cast<int>(t.size()); }
};

// A length in metres as text in millimetres, 4 significant digits ("12.35 mm"), for notes.
inline std::string Mm(double metres) { return Printf("%.4g", metres * 1e3) + " mm"; }

// The median of v (the mean of the two middle values for an even count); v not empty.
inline double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  const double upper = v[mid];
  if (v.size() % 2) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + mid));
}

// The image speed at each of the frames (t, u, v) in time order, px per frame interval (the
// median Δt): the move between its neighbours i − 1 and i + 1 (one-sided at the ends) over their
// time apart. 0 for a single frame.
inline std::vector<double> PixelsPerFrame(const std::vector<double>& t, const std::vector<double>& u,
                                          const std::vector<double>& v) {
  const int n = static_cast<int>(t.size());
  std::vector<double> speed(n, 0.0);
  if (n < 2) return speed;
  std::vector<double> steps;
  for (int i = 1; i < n; ++i) steps.push_back(t[i] - t[i - 1]);
  const double frame = Median(steps);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(i - 1, 0), b = std::min(i + 1, n - 1);
    const double s = std::hypot(u[b] - u[a], v[b] - v[a]) / (t[b] - t[a]) * frame;
    speed[i] = std::isfinite(s) ? s : 0.0;
  }
  return speed;
}

// Mean and sample standard deviation of v[begin, end).
inline std::pair<double, double> MeanAndSd(const std::vector<double>& v, int begin, int end) {
  const int n = end - begin;
  const double mean = std::accumulate(v.begin() + begin, v.begin() + end, 0.0) / n;
  double ss = 0;
  for (int i = begin; i < end; ++i) ss += (v[i] - mean) * (v[i] - mean);
  return {mean, n > 1 ? std::sqrt(ss / (n - 1)) : 0.0};
}

}  // namespace uphill::internal
