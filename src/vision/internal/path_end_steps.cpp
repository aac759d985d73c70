#include "path_end_steps.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "linear_light.hpp"

namespace uphill::internal {
namespace {

double Median(std::vector<double>& v) {
  if (v.empty()) return -1;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

PathEndSteps MeasurePathEndSteps(const OutlineGeometry& g, const FrameView& view, const std::array<float, 256>& table,
                                 double x, double z, const Eigen::Vector2d& tangent_px, const Eigen::Vector2d& smear_px) {
  constexpr int kRays = 96;
  const double end_cos = std::cos(20.0 * M_PI / 180);
  std::vector<Eigen::Vector3d> points = g.OutlinePoints(x, z, kRays);
  points.emplace_back(x, 0, z);
  const std::vector<Eigen::Vector2d> image = ProjectApparatusPoints(g.cal.camera, g.cal.pose, points);
  const Eigen::Vector2d centre = image[kRays];
  const cv::Mat& bgr = view.bgr;
  const Eigen::Vector2d origin(view.origin.x, view.origin.y);
  std::vector<double> leading, trailing;
  for (int k = 0; k < kRays; ++k) {
    const Eigen::Vector2d dir = (image[k] - centre).normalized();
    const double along = dir.dot(tangent_px);
    if (std::abs(along) <= end_cos) continue;
    // Past the ramp: half the smear along the ray, the point spread, and a pixel's sampling.
    const double reach = 0.5 * std::abs(smear_px.dot(dir)) + 2 * g.sigma_px + 1;
    cv::Vec3f in(0, 0, 0), out(0, 0, 0);
    bool ok = true;
    for (int i = 0; i < 3 && ok; ++i) {
      const Eigen::Vector2d pin = image[k] - (reach + i) * dir - origin, pout = image[k] + (reach + i) * dir - origin;
      ok = std::min({pin.x(), pin.y(), pout.x(), pout.y()}) >= 1 && std::max(pin.x(), pout.x()) < bgr.cols - 2 &&
           std::max(pin.y(), pout.y()) < bgr.rows - 2;
      if (ok && g.occluder)
        ok = !g.occluder->at<std::uint8_t>(static_cast<int>(pout.y() + origin.y() + 0.5), static_cast<int>(pout.x() + origin.x() + 0.5)) &&
             !g.occluder->at<std::uint8_t>(static_cast<int>(pin.y() + origin.y() + 0.5), static_cast<int>(pin.x() + origin.x() + 0.5));
      if (ok) in += SampleLinear(bgr, table, pin.x(), pin.y()), out += SampleLinear(bgr, table, pout.x(), pout.y());
    }
    if (!ok) continue;
    const double step = cv::norm(in - out) / 3;
    (along > 0 ? leading : trailing).push_back(step);
  }
  PathEndSteps s;
  if (static_cast<int>(leading.size()) >= PathEndSteps::kMinRays) s.leading = Median(leading);
  if (static_cast<int>(trailing.size()) >= PathEndSteps::kMinRays) s.trailing = Median(trailing);
  return s;
}

}  // namespace uphill::internal
