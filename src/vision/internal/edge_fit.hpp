// The tracker's fast path: the body's outline located as grey-level edges and fitted with Ceres.
//
// Rays from the predicted centre's image cross `points` tangent points of the predicted outline
// (the cone of rays tangent to the body, outline_fit.hpp's OutlineGeometry). Along each, the grey
// level of the frame (8-bit, smoothed by a Gaussian of σ = 1 px) is sampled every half pixel over
// ±half_width; the edge is the centroid of the gradient above half its strongest peak of the
// expected polarity (the middle of the edge's ramp: for a short motion blur, the edge at
// mid-exposure). Rays through the near rail's band are not used. The centre (x, z) and a uniform
// edge bias (prior N(0, 0.5 px)) are fitted to the edge points' viewing rays with a Cauchy loss
// (scale 0.5 px): the angle between each ray and the centre's direction minus the outline's half
// angle, in pixels. A second, narrow pass (±2.5 px) around the first fit when it moved more than a
// pixel or lost edges.
//
// What it assumes, and the tracker checks before trusting it (ball_tracker.cpp, "fast path"):
// the body differs from its surroundings in grey level all round, the motion blur is short
// against the radius, the body has no inner edges near its outline, the shutter is global. Where
// these hold it is about 0.05–0.25 px RMS at a cost of one small Ceres solve (3 parameters,
// ≤ 96 residuals) per frame; where they do not, its edges are biased (a blurred edge in the
// camera's gamma-encoded grey is not centred at mid-exposure) or wrong (a painted band's edge).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "outline_fit.hpp"

namespace uphill::internal {

struct EdgeFitOutcome {
  bool ok = false;
  double x = 0, z = 0;   // fitted centre, m
  int attempted = 0;     // rays inside the frame and off the rail
  int edge_points = 0;   // rays where an edge was found
  int inliers = 0;       // edge points within 1 px of the fitted outline
  double rms_px = 0;     // RMS residual of the inliers, px
  double contrast = 0;   // median |grey step| across the outline, 8-bit levels
};

class EdgeFit {
 public:
  EdgeFit(const OutlineGeometry& geometry, int points) : geometry_(geometry), points_(points) {}

  // Fits the outline near the body centred at (x, z) (m), the edge searched ±half_width px.
  EdgeFitOutcome Measure(const cv::Mat& bgr, double x, double z, double half_width);
  // Forget the edge polarity (a body found anew).
  void Reset() { polarity_ = 0; }
  int points() const { return points_; }

 private:
  EdgeFitOutcome FitOnce(const cv::Mat& bgr, double x, double z, double half_width);
  bool InFront(double x, double z) const;

  const OutlineGeometry& geometry_;
  int points_;
  int polarity_ = 0;  // sign of the grey step from inside to outside the body; 0: unknown
};

}  // namespace uphill::internal
