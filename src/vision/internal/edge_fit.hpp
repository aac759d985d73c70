// The tracker's fast path: the body's outline located as edges of the linear luminance and
// fitted to them (ceres::TinySolver, edge_rays_fit.hpp).
//
// Rays from the predicted centre's image cross `points` tangent points of the predicted outline
// (the cone of rays tangent to the body, outline_fit.hpp's OutlineGeometry). Along each, the
// frame's colour in linear light (each channel decoded by the camera's transfer curve,
// linear_light.hpp, on a 0..255 scale; smoothed by a Gaussian of σ = 1 px) is sampled every half
// pixel over ±half_width and read in one channel: the luminance (Rec. 709 weights), or, where its
// grey edge is weak (a gradient below 6 levels per px) and the colours at the ray's two ends
// differ mostly in hue (a colour step more than 4 times the grey step: a blue ball on a green
// cloth as grey as it), the colour along their difference. The edge is the centroid of that
// channel's gradient above half its strongest peak of the expected polarity (an edge read in hue
// rises outward by construction). In linear light a motion-blurred edge is a
// blend of body and background whose ramp runs straight across the edge's sweep, so that
// centroid is the outline at mid-exposure (up to the outline's curvature over the sweep, about
// blur²/(16·radius) at the sides, the same on opposite sides); in the camera's encoded grey the
// ramp bends and its centroid moves toward the darker side by a fraction of the blur. Rays
// through the near rail's band are not used. The centre (x, z) and a uniform edge bias are
// fitted to the edge points' viewing rays with a Cauchy loss (edge_rays_fit.hpp). A second,
// narrow pass (±2.5 px) around the first fit when it moved more than a pixel or lost edges.
//
// What it assumes, and the tracker checks before trusting it (ball_tracker.cpp, "fast path"):
// the body differs from its surroundings in luminance all round (the median grey step; the
// edges themselves may be read in hue), the motion blur is short
// against the radius, the body has no inner edges near its outline, the shutter is global. Where
// these hold it is within about 0.1 px RMS (docs/benchmarks.md, `uphill bench track`), at a
// cost of one small solve (3 parameters, ≤ 97 residuals) per frame; where they do
// not, its edges are wrong (a painted band's edge, a body as bright as its table).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <vector>

#include "edge_rays_fit.hpp"
#include "linear_light.hpp"
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
  // The solve's inputs and result, for SectorSpreadPx: the edge points' viewing rays, the
  // sector of each (kOutlineSectors equal sectors of the rays searched, in order around the
  // outline), and the fit.
  EdgeRays problem;
  std::vector<int> sectors;
  EdgeRaysSolution solution;
};

// How much the centre depends on which part of the outline its edges came from: the
// delete-one-group jackknife standard error of the centre's image position (px, both axes
// together) over kOutlineSectors sectors of 45°, each left out in turn and the rest fitted
// again (FitEdgeRays from the whole fit; sectors without edge points, or whose removal leaves
// too few, are not counted). A sharp outline found all round agrees with itself to a few
// hundredths of a pixel (the test). Where one part of it was found off the limb (a print's or a
// reflection's edge beside it, the table's texture next to a faint limb, a limb the colour of
// the table), leaving that part out moves the centre, and the spread shows it: on 45 ray-traced
// scenes of bodies at rest (four random draws), the centre's error lay within 2.45 times the
// larger of the spread and 0.08 px in 43 (docs/track.md, "Output"). A disturbance wider
// than a sector is partly missed: leaving one sector out leaves its neighbour's share. It is an
// error of the frame's centre that the frame's own scatter cannot show: frames at rest share it.
// 0 when fewer than 3 sectors count. Costs kOutlineSectors small solves: called for a frame's
// reported fit only.
double SectorSpreadPx(const OutlineGeometry& geometry, const EdgeFitOutcome& fit);

// Sectors of the outline's rays for SectorSpreadPx: 45° each.
inline constexpr int kOutlineSectors = 8;

// Edge points a fit needs: below it EdgeFitOutcome::ok is false (three parameters, and enough
// points beyond them for the Cauchy loss to set outliers aside).
inline constexpr int kEdgeFitMinPoints = 8;

class EdgeFit {
 public:
  // bgr frames are 8-bit BGR encoded by `transfer` (linear_light.hpp).
  EdgeFit(const OutlineGeometry& geometry, int points, Transfer transfer);

  // Fits the outline near the body centred at (x, z) (m), the edge searched ±half_width px.
  EdgeFitOutcome Measure(const cv::Mat& bgr, double x, double z, double half_width);
  // Forget the edge polarity (a body found anew).
  void Reset() { polarity_ = 0; }
  // Look for edges of either sign on every ray and set no polarity, while `either` holds: a
  // two-tone body on a background between its two greys steps up on one half of its outline and
  // down on the other.
  void EitherPolarity(bool either) { either_polarity_ = either; }
  int points() const { return points_; }

 private:
  EdgeFitOutcome FitOnce(const cv::Mat& bgr, double x, double z, double half_width);
  bool InFront(double x, double z) const;

  const OutlineGeometry& geometry_;
  int points_;
  std::array<float, 256> linear_;  // each 8-bit code's linear value, 0..255
  bool either_polarity_ = false;
  int polarity_ = 0;  // sign of the grey step from inside to outside the body; 0: unknown
};

}  // namespace uphill::internal
