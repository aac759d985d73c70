// The near rail's band in the picture: the rail on the camera's side passes in front of the body,
// and a ray across the body's outline that meets it sees the rod, not the outline. The tracker
// uses no ray through the band (its occluder).
//
// The band follows the rail's axis x ↦ (x, ±x·tan(α/2), x·tan θ) where the lens model holds, at
// one width all along: the rod's widest in the picture, widened by 2.5 px for the point spread
// and the sampling. One width rather than the rod's local width: a rod's highlight and its shadow
// reach beyond its geometric width, and on random ray-traced scenes a band at the local width let
// them into the outline fits. The widest is taken over the whole rail as far as the lens model
// holds (the widest reach, before the picture's edge is known to bound it), unless a band that
// wide hides the body's outline at a quarter or more of the places along the path where a band
// at the rod's widest in the picture would not (a thick rod near the camera, outside the
// picture): then over the part of the rail whose band reaches into the picture. Where
// the band still hides the outline at two places in three or more (a thick rod between a low
// camera and a small ball), it is drawn at the rod's own width at each point: the tracker would
// be blind over most of the path, and a rod's highlight is the smaller risk.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>

#include "model/scene.hpp"
#include "outline_fit.hpp"

namespace uphill::internal {

// CV_8U, the picture's size: 1 on the band. `rod`: the rods' radius, m; `within_lens`: whether
// the lens model maps a camera-frame point; the path's range [x_lo, x_hi], m.
cv::Mat DrawNearRailBand(const Scene& scene, const OutlineGeometry& geometry, double rod,
                         const std::function<bool(const Eigen::Vector3d&)>& within_lens, double x_lo, double x_hi);

}  // namespace uphill::internal
