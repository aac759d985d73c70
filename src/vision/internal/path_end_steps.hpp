// The colour step across a fitted outline at the body's two ends along the rods: the evidence
// that a body is there. A body between the rails has its top and bottom outline beside the
// rods' edges, which run along the path: a disc anywhere along the gap meets them just as well,
// also where the body was before it fell through. Only the outline's ends along the rods tell
// the body from the gap, and there an empty gap has no step (the table on both sides).
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

#include "outline_fit.hpp"

namespace uphill::internal {

struct PathEndSteps {
  // The median over each end's rays of |inside − outside| (linear RGB, Euclidean: a step in hue
  // counts), each side the mean of three samples past the smear's ramp and the point spread;
  // -1 where fewer than kMinRays rays of that end lie in the picture and off the near rail's band.
  double leading = -1, trailing = -1;
  static constexpr int kMinRays = 2;
};

// The body centred at (x, 0, z) in `view` (a frame, or a window of one); `tangent_px`: the rods'
// direction in the image at the centre (unit); `smear_px`: the smear over the exposure in the
// image. Its ends are the rays within 20° of the rods' direction: wider, they reach the rods
// above and below a body that sits deep between them.
PathEndSteps MeasurePathEndSteps(const OutlineGeometry& geometry, const FrameView& view, const std::array<float, 256>& table,
                                 double x, double z, const Eigen::Vector2d& tangent_px, const Eigen::Vector2d& smear_px);

}  // namespace uphill::internal
