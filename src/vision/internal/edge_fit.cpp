#include "edge_fit.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "edge_rays_fit.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kStep = 0.5;             // px between profile samples
constexpr double kNarrowHalfWidth = 2.5;  // px, second pass around the first fit
constexpr double kInlierPx = 1.0;         // |residual| below this: inlier
constexpr double kMinGradient = 2.0;      // levels per px: weaker is no edge
// An edge is read in hue where its grey edge is weak (a gradient peak below kWeakGreyEdge levels
// per px) and the colour step across the ray exceeds the grey step kHueEdge times: a blue ball on
// a green cloth of its grey. Where the grey edge is clear, a hue edge is more often a print's or
// a reflection's: on random ray-traced scenes, reading hue at a ratio of 2, or on clear grey
// edges too, cost printed and glossy bodies more than it gained.
constexpr double kWeakGreyEdge = 6.0, kHueEdge = 4.0;
constexpr int kEndSamples = 4;  // samples at each end of a ray that give its inside and outside colours
const cv::Vec3f kLuminance(0.0722f, 0.7152f, 0.2126f);  // B, G, R: Rec. 709 luminance

cv::Vec3f Bilinear(const cv::Mat& img, double x, double y) {
  const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
  const float fx = static_cast<float>(x - i), fy = static_cast<float>(y - j);
  const cv::Vec3f* r0 = img.ptr<cv::Vec3f>(j);
  const cv::Vec3f* r1 = img.ptr<cv::Vec3f>(j + 1);
  const cv::Vec3f top = r0[i] + fx * (r0[i + 1] - r0[i]);
  const cv::Vec3f bottom = r1[i] + fx * (r1[i + 1] - r1[i]);
  return top + fy * (bottom - top);
}

}  // namespace

bool EdgeFit::InFront(double x, double z) const {
  const OutlineGeometry& g = geometry_;
  return (g.cal.pose.rotation * Vector3d(x, 0, z) + g.cal.pose.translation).z() > 2 * g.a &&
         (Vector3d(x, 0, z) - g.eye).norm() > 2 * std::max(g.a, g.a / g.s);
}

EdgeFitOutcome EdgeFit::FitOnce(const cv::Mat& bgr, double x, double z, double half_width) {
  const OutlineGeometry& g = geometry_;
  EdgeFitOutcome fit;
  if (!InFront(x, z)) return fit;
  const int n = points_;
  std::vector<Vector3d> points = g.OutlinePoints(x, z, n);
  points.emplace_back(x, 0, z);
  const std::vector<Vector2d> image = ProjectApparatusPoints(g.cal.camera, g.cal.pose, points);
  const Vector2d q = image.back();
  // Region of interest: all search segments, plus the smoothing kernel's reach.
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (int k = 0; k < n; ++k) {
    u0 = std::min(u0, image[k].x()), u1 = std::max(u1, image[k].x());
    v0 = std::min(v0, image[k].y()), v1 = std::max(v1, image[k].y());
  }
  const double pad = half_width + 6;
  if (!(u1 - u0 < 4 * bgr.cols && v1 - v0 < 4 * bgr.rows)) return fit;
  const cv::Rect full(0, 0, bgr.cols, bgr.rows);
  const cv::Rect roi = cv::Rect(cv::Point(static_cast<int>(std::floor(u0 - pad)), static_cast<int>(std::floor(v0 - pad))),
                                cv::Point(static_cast<int>(std::ceil(u1 + pad)), static_cast<int>(std::ceil(v1 + pad)))) &
                       full;
  if (roi.width < 8 || roi.height < 8) return fit;
  // The decoded channels in linear light, scaled to 0..255 so that the thresholds read in 8-bit
  // levels: only in linear light is a blurred edge's ramp a straight blend whose middle is the
  // outline at mid-exposure. Smoothed once; the luminance (Rec. 709) is their weighted sum.
  cv::Mat smooth(roi.size(), CV_32FC3);
  for (int y = 0; y < roi.height; ++y) {
    const std::uint8_t* in = bgr.ptr<std::uint8_t>(roi.y + y) + 3 * roi.x;
    cv::Vec3f* out = smooth.ptr<cv::Vec3f>(y);
    for (int x = 0; x < roi.width; ++x, in += 3) out[x] = {linear_[in[0]], linear_[in[1]], linear_[in[2]]};
  }
  cv::GaussianBlur(smooth, smooth, cv::Size(7, 7), 1.0);

  const int samples = 2 * static_cast<int>(std::ceil(half_width / kStep)) + 1;
  const double start = -(samples / 2) * kStep;
  std::vector<cv::Vec3f> colours(samples);
  std::vector<double> luminance(samples), profile(samples), gradient(samples);
  std::vector<Vector2d> edges;
  std::vector<double> contrasts;
  std::vector<int> signs;
  std::vector<int> sectors;  // of each edge point's ray, for the sector spread
  const cv::Mat& occluder = *g.occluder;
  for (int k = 0; k < n; ++k) {
    const Vector2d radial = image[k] - q;
    if (radial.norm() < 1) continue;
    const Vector2d dir = radial.normalized();
    const Vector2d first = image[k] + start * dir, last = image[k] - start * dir;
    // Inside the region (with one pixel for the interpolation) and the frame.
    auto inside = [&](const Vector2d& p) {
      return p.x() >= roi.x + 3 && p.y() >= roi.y + 3 && p.x() <= roi.x + roi.width - 4 && p.y() <= roi.y + roi.height - 4;
    };
    if (!inside(first) || !inside(last)) continue;
    bool hidden = false;
    for (int m = 0; m <= 4 && !hidden; ++m) {
      const Vector2d p = first + (last - first) * (m / 4.0);
      hidden = occluder.at<std::uint8_t>(static_cast<int>(std::lround(p.y())), static_cast<int>(std::lround(p.x()))) != 0;
    }
    if (hidden) continue;
    ++fit.attempted;
    for (int i = 0; i < samples; ++i) {
      const Vector2d p = first + (i * kStep) * dir;
      colours[i] = Bilinear(smooth, p.x() - roi.x, p.y() - roi.y);
      luminance[i] = kLuminance.dot(colours[i]);
    }
    // Gradient (outward) of `profile` and its strongest peak of the expected polarity.
    int best = -1;
    double best_g = 0;
    const auto strongest = [&](int expected) {
      best = -1, best_g = 0;
      std::fill(gradient.begin(), gradient.end(), 0.0);
      for (int i = 1; i + 1 < samples; ++i) {
        gradient[i] = (profile[i + 1] - profile[i - 1]) / (2 * kStep);
        const double signed_g = expected == 0 ? std::abs(gradient[i]) : expected * gradient[i];
        if (i >= 2 && i + 2 < samples && signed_g > best_g) best_g = signed_g, best = i;
      }
    };
    profile = luminance;
    strongest(polarity_);
    // Where the grey edge is weak (a peak below kWeakGreyEdge) and the colours across the ray
    // differ mostly in hue (the colour step between the window's ends, Δ = outside − inside, more
    // than kHueEdge times the grey step), the edge is read along Δ/|Δ| instead, in which it rises
    // outward by |Δ|. A blend of two colours is a blend along Δ, so the ramp's middle stays the
    // outline at mid-exposure.
    bool by_hue = false;
    if (best_g < kWeakGreyEdge) {
      cv::Vec3f delta(0, 0, 0);
      for (int i = 0; i < kEndSamples; ++i) delta += colours[samples - 1 - i] - colours[i];
      delta *= 1.0f / kEndSamples;
      const double hue_step = cv::norm(delta);
      by_hue = hue_step > kHueEdge * std::abs(kLuminance.dot(delta));
      if (by_hue) {
        delta *= static_cast<float>(1 / hue_step);
        for (int i = 0; i < samples; ++i) profile[i] = delta.dot(colours[i]);
        strongest(1);
      }
    }
    if (best < 0 || best_g < kMinGradient) continue;
    // Centroid of the gradient above half its peak: the middle of the edge's ramp. For a sharp
    // edge that is the peak; for a motion-blurred one (a ramp as long as the blur, with a flat
    // gradient) it is the edge at mid-exposure, where a peak finder would wander.
    const int sign = gradient[best] > 0 ? 1 : -1;
    const double half = 0.5 * std::abs(gradient[best]);
    int lo = best, hi = best;
    while (lo > 1 && sign * gradient[lo - 1] > half) --lo;
    while (hi + 2 < samples && sign * gradient[hi + 1] > half) ++hi;
    double weight = 0, moment = 0;
    for (int i = lo; i <= hi; ++i) {
      const double w = sign * gradient[i] - half;
      weight += w;
      moment += w * i;
    }
    const double along = start + (moment / weight) * kStep;
    edges.push_back(image[k] + along * dir);
    sectors.push_back(k * kOutlineSectors / n);
    // The grey step across the edge (what the fast path's trust reads), and its sign; 0 for an
    // edge read in hue, which says nothing of the grey polarity.
    const double grey_step = luminance[std::min(samples - 1, hi + 3)] - luminance[std::max(0, lo - 3)];
    contrasts.push_back(grey_step);
    signs.push_back(by_hue ? 0 : sign);
  }
  fit.edge_points = static_cast<int>(edges.size());
  if (fit.edge_points < kEdgeFitMinPoints) return fit;
  {
    std::vector<double> c = contrasts;
    for (double& v : c) v = std::abs(v);
    std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
    fit.contrast = c[c.size() / 2];
  }

  // Viewing rays of the edge points, in the scaled space.
  EdgeRays problem;
  problem.eye = g.eye_s;
  problem.a = g.a;
  problem.px_per_rad = g.PxPerRad(x, z);
  problem.rays.reserve(edges.size());
  for (const Vector2d& m : UndistortPixels(g.cal.camera, edges)) {
    Vector3d r = g.to_apparatus * Vector3d(m.x(), m.y(), 1.0);
    r.y() *= g.s;
    problem.rays.push_back(r.normalized());
  }
  const EdgeRaysSolution solution = FitEdgeRays(problem, x, z);
  if (!solution.finite || !InFront(solution.x, solution.z)) return fit;

  double sum2 = 0;
  int votes = 0, voters = 0;  // the grey edges' polarity
  for (size_t k = 0; k < problem.rays.size(); ++k) {
    const double res = EdgeRayResidualPx(problem, problem.rays[k], solution.x, solution.z, solution.bias);
    if (std::abs(res) < kInlierPx) {
      ++fit.inliers;
      sum2 += res * res;
      votes += signs[k];
      voters += signs[k] != 0;
    }
  }
  fit.ok = fit.inliers >= 3;
  fit.x = solution.x;
  fit.z = solution.z;
  fit.rms_px = fit.inliers ? std::sqrt(sum2 / fit.inliers) : 0;
  fit.problem = std::move(problem);
  fit.sectors = std::move(sectors);
  fit.solution = solution;
  if (polarity_ == 0 && voters > 0 && !either_polarity_) polarity_ = votes >= 0 ? 1 : -1;
  return fit;
}

double SectorSpreadPx(const OutlineGeometry& geometry, const EdgeFitOutcome& fit) {
  if (!fit.ok || fit.sectors.size() != fit.problem.rays.size()) return 0;
  const EdgeRaysSolution& all = fit.solution;
  const Vector2d centre = geometry.Project(all.x, all.z);
  std::vector<Vector2d> shifts;
  for (int sector = 0; sector < kOutlineSectors; ++sector) {
    EdgeRays kept = fit.problem;
    kept.rays.clear();
    for (std::size_t i = 0; i < fit.sectors.size(); ++i)
      if (fit.sectors[i] != sector) kept.rays.push_back(fit.problem.rays[i]);
    if (kept.rays.size() == fit.problem.rays.size() || kept.rays.size() < static_cast<std::size_t>(kEdgeFitMinPoints)) continue;
    const EdgeRaysSolution without = FitEdgeRays(kept, all.x, all.z, all.bias);
    if (without.finite) shifts.push_back(geometry.Project(without.x, without.z) - centre);
  }
  const int groups = static_cast<int>(shifts.size());
  if (groups < 3) return 0;
  Vector2d mean = Vector2d::Zero();
  for (const Vector2d& d : shifts) mean += d;
  mean /= groups;
  double sum2 = 0;
  for (const Vector2d& d : shifts) sum2 += (d - mean).squaredNorm();
  return std::sqrt(sum2 * (groups - 1) / groups);
}

EdgeFit::EdgeFit(const OutlineGeometry& geometry, int points, Transfer transfer) : geometry_(geometry), points_(points) {
  const std::array<float, 256> linear = LinearTable(transfer);
  for (int k = 0; k < 256; ++k) linear_[k] = 255.0f * linear[k];
}

EdgeFitOutcome EdgeFit::Measure(const cv::Mat& bgr, double x, double z, double half_width) {
  EdgeFitOutcome first = FitOnce(bgr, x, z, half_width);
  if (!first.ok) return first;
  const Vector2d moved = geometry_.Project(first.x, first.z) - geometry_.Project(x, z);
  if (moved.norm() < 1.0 && first.inliers >= 0.9 * first.edge_points) return first;
  EdgeFitOutcome second = FitOnce(bgr, first.x, first.z, kNarrowHalfWidth);
  return second.ok ? second : first;
}

}  // namespace uphill::internal
