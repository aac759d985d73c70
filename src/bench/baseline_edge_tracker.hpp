// The baseline beside the tracker in `uphill bench track --random`: the edge-fit tracker as it
// stood before the appearance and smear models were added (the project's commit efef5cc), kept
// whole so that every benchmark run measures the tracker against the simplest method that
// worked. It is not a product: nothing but the benchmark links it. Its outline geometry, edge
// search and near-rail mask repeat what src/vision grew from them, on purpose: sharing that code
// would move the baseline whenever the tracker changes.
//
// What it does: grey-level gradient edges along rays across the outline predicted at the last
// positions (constant acceleration over three frames), a Cauchy-robust Ceres fit of the centre
// (x, z) on the plane y = 0 and a uniform edge bias; acquisition by the strongest median step
// across outlines along the centre path. One polarity per clip (the step's sign, voted at
// acquisition), no background model, no smear, no rolling shutter: a body darker on one side
// than the table and lighter on the other loses half its edges.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <opencv2/core.hpp>

#include "model/scene.hpp"
#include "vision/camera.hpp"

namespace uphill::bench {

struct BaselineOptions {
  std::optional<Eigen::Vector2d> init_uv;  // raw pixel near the centre in the first frame
  int outline_points = 96;                 // edge searches per frame
  double search_half_width_px = 6;         // along each ray, either side of the predicted outline
  double min_inlier_fraction = 0.35;       // of the outline points; below: lost
  double rail_radius = 0.003;              // m: drawn width of line rails (scene without rods)
  double min_contrast = 12;                // grey levels across the outline to accept a body
};

struct BaselineObservation {
  bool found = false;
  double u = 0, v = 0;       // raw pixel of the fitted centre
  double radius_px = 0;      // mean distance of the outline from (u, v)
  double x = 0, z = 0;       // centre, m, apparatus frame
  double quality = 0;        // [0, 1]: inlier fraction × exp(−rms² / 2(0.5 px)²); 0 when not found
  int edge_points = 0, inliers = 0;
  double rms_px = 0;         // RMS residual of the inliers
};

class BaselineEdgeTracker {
 public:
  // Throws InputError for a double cone (kDoubleConeRefusal) or unusable intrinsics or options.
  BaselineEdgeTracker(const Scene& scene, const SceneCalibration& calibration, const BaselineOptions& options = {});
  ~BaselineEdgeTracker();
  BaselineEdgeTracker(BaselineEdgeTracker&&) noexcept;

  // The next frame (8-bit BGR or grey, the calibration's size; InputError otherwise).
  BaselineObservation Track(const cv::Mat& frame);

  // The raw-pixel outline of a body centred at (x, 0, z) (n points).
  std::vector<Eigen::Vector2d> Outline(double x, double z, int n) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill::bench
