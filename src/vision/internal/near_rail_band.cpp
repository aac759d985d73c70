#include "near_rail_band.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "vision/camera.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kMarginPx = 2.5;  // the point spread and the sampling
constexpr int kRailSamples = 400;
// The body's outline is usable at a place where a third of these rays clear the band (the
// search's rule, Candidates in tracker_acquire.cpp), looked for at this many places.
constexpr int kOutlineRays = 32, kPlacesAlongPath = 48;
// A band that hides the body's outline at this share of the places or more leaves the tracker
// blind over most of the path (a thick rod between a low camera and a small ball): it is drawn at
// the rod's own width instead. No scene looked at while building the tracker reaches it once
// kUncovered has chosen the band (one hid 73 % of its places at the rail's widest, 27 % at the
// widest in the picture); it stays for a thick rod near the camera and inside the picture.
constexpr double kMostlyHidden = 2.0 / 3.0;
// A band at the rod's widest in the picture is drawn instead of the rail's widest where it shows
// the body's outline at this share of the places more: the rail's widest part is then near the
// camera and outside the picture, and a band at its width hides the body over a stretch of the
// path where the rod itself is far narrower. On the random scenes looked at while building the
// tracker it showed 0.69 and 0.88 more (bands 145 px wide that hid every place: the body found in
// every frame at the narrower band, in none at the wider), 0.46 (a dotted ball behind 9 mm rods, a
// low camera: 40 of 40 frames at 0.087 px), 0.35 (a dotted spheroid at rest behind 14 mm rods: at
// the rail's widest the search took a patch of the table 265 px off; at the narrower band 40 of 40
// at 0.095 px) and 0.38 (a glossy spheroid in front of steel rods: 0.19 px against 0.11 px, 0.17
// px low in every frame: rays across the rods enter its fit); 0.08 at most on the other 251.
constexpr double kUncovered = 0.25;

struct RailTrace {
  std::vector<cv::Point> line;  // 1/16 px
  std::vector<double> half_widths;  // px: the rod's own at each point of `line`
  double widest_px = 0, widest_in_picture_px = 0;
};

RailTrace TraceNearRail(const Scene& scene, const SceneCalibration& cal, double rod, double side,
                        const std::function<bool(const Vector3d&)>& within_lens) {
  const Rails& rails = scene.rails();
  const Vector3d axis(1, side * rails.tan_half_alpha, rails.tan_theta);
  const double x_end = 1.5 * scene.x_max() + 0.2;
  const double width = cal.camera.width, height = cal.camera.height;
  RailTrace trace;
  for (int i = 0; i <= kRailSamples; ++i) {
    const Vector3d pc = cal.pose.rotation * (axis * (x_end * i / kRailSamples)) + cal.pose.translation;
    // Only where the lens model holds: beyond its reach a rail point far outside the picture would
    // be drawn inside it (a k3 < 0 lens folds back).
    if (pc.z() <= 0.05 || !within_lens(pc)) continue;
    const Vector2d q = ProjectCameraPoint(cal.camera, pc);
    if (std::abs(q.x()) > 1e5 || std::abs(q.y()) > 1e5) continue;
    trace.line.emplace_back(static_cast<int>(std::lround(q.x() * 16)), static_cast<int>(std::lround(q.y() * 16)));
    const double half_width = rod * cal.camera.fx / pc.z(), reach = half_width + kMarginPx;
    trace.half_widths.push_back(half_width);
    trace.widest_px = std::max(trace.widest_px, half_width);
    if (q.x() > -reach && q.y() > -reach && q.x() < width + reach && q.y() < height + reach)
      trace.widest_in_picture_px = std::max(trace.widest_in_picture_px, half_width);
  }
  return trace;
}

int Thickness(double half_width) { return std::max(1, static_cast<int>(std::ceil(2 * (half_width + kMarginPx)))); }

cv::Mat Draw(const RailTrace& trace, double half_width, const cv::Size& size) {
  cv::Mat band = cv::Mat::zeros(size, CV_8U);
  if (trace.line.size() >= 2) cv::polylines(band, trace.line, false, cv::Scalar(1), Thickness(half_width), cv::LINE_8, 4);
  return band;
}

cv::Mat DrawAtTheRodsOwnWidth(const RailTrace& trace, const cv::Size& size) {
  cv::Mat band = cv::Mat::zeros(size, CV_8U);
  for (size_t i = 1; i < trace.line.size(); ++i)
    cv::line(band, trace.line[i - 1], trace.line[i], cv::Scalar(1),
             Thickness(std::max(trace.half_widths[i - 1], trace.half_widths[i])), cv::LINE_8, 4);
  return band;
}

// The places along the path (those the lens model maps), and those of them where fewer than a
// third of the body's outline rays (their samples just outside the outline, in the picture) clear
// the band.
struct HiddenPlaces {
  int hidden = 0, places = 0;
  double share() const { return places ? static_cast<double>(hidden) / places : 1.0; }
};

HiddenPlaces Hidden(const cv::Mat& band, const OutlineGeometry& g, const Scene& scene, double x_lo, double x_hi,
                    const std::function<bool(const Vector3d&)>& within_lens) {
  int places = 0, hidden = 0;
  for (int i = 0; i < kPlacesAlongPath; ++i) {
    const double x = x_lo + (x_hi - x_lo) * (i + 0.5) / kPlacesAlongPath, z = scene.At(x).z;
    if (!within_lens(g.cal.pose.rotation * Vector3d(x, 0, z) + g.cal.pose.translation)) continue;
    std::vector<Vector3d> points = g.OutlinePoints(x, z, kOutlineRays);
    points.emplace_back(x, 0, z);
    const std::vector<Vector2d> image = ProjectApparatusPoints(g.cal.camera, g.cal.pose, points);
    int clear = 0;
    for (int k = 0; k < kOutlineRays; ++k) {
      const Vector2d out = image[k] + 3.0 * (image[k] - image.back()).normalized();
      const int u = static_cast<int>(std::lround(out.x())), v = static_cast<int>(std::lround(out.y()));
      clear += u >= 0 && v >= 0 && u < band.cols && v < band.rows && !band.at<std::uint8_t>(v, u);
    }
    ++places;
    hidden += clear < kOutlineRays / 3;
  }
  return {hidden, places};
}

}  // namespace

cv::Mat DrawNearRailBand(const Scene& scene, const OutlineGeometry& geometry, double rod,
                         const std::function<bool(const Vector3d&)>& within_lens, double x_lo, double x_hi) {
  const double side = geometry.eye.y() < 0 ? -1.0 : 1.0;
  const RailTrace trace = TraceNearRail(scene, geometry.cal, rod, side, within_lens);
  const cv::Size size(geometry.cal.camera.width, geometry.cal.camera.height);
  cv::Mat band = Draw(trace, trace.widest_px, size);
  const auto hidden = [&](const cv::Mat& b) { return Hidden(b, geometry, scene, x_lo, x_hi, within_lens); };
  HiddenPlaces at_widest = hidden(band);
  if (trace.widest_in_picture_px < trace.widest_px) {
    cv::Mat in_picture = Draw(trace, trace.widest_in_picture_px, size);
    const HiddenPlaces in = hidden(in_picture);  // the same places: the band's width alone differs
    if (at_widest.hidden - in.hidden >= kUncovered * at_widest.places) band = std::move(in_picture), at_widest = in;
  }
  if (at_widest.share() >= kMostlyHidden) band = DrawAtTheRodsOwnWidth(trace, size);
  return band;
}

}  // namespace uphill::internal
