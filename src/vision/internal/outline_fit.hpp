// One frame's measurement of the body: the smeared outline (smeared_outline.hpp) fitted with Ceres
// to the pixels across it, in linear light, against the background.
//
// Rays: from the predicted centre's image through `rays` points of the predicted outline (the
// cone's tangent points), each sampled over a window that holds the edge's whole sweep during the
// exposure (the predicted smear projected on the ray, the inward reach of the smear's sides) plus
// the prediction's uncertainty and the point spread. A ray that leaves the picture or crosses the
// near rail's band (the occluder) is not used: hidden edges are not edges.
//
// Model of a ray's samples i (linear RGB, 3 residuals each):
//   I_i = (1 − c_i)·g·B_i + c_i·(F_k + h_i·G_k)
// c_i the coverage of the sample's viewing ray, g·B_i the background at the sample (the
// background model times this frame's gain), F_k the body's colour at this ray's limb and G_k
// the amplitude of its shading profile inside the limb, h_i = min(1, √(2d_i/r)) (d_i the
// sample's depth inside the predicted outline, r the outline's radius: the surface turns toward
// the camera as √(2d/r) there, so the shading of a matte body changes fastest right at its
// outline, and a limb colour alone put the edge off it). F_k and G_k are nuisances solved in
// closed form for every evaluation (variable projection, with Kaufman's Jacobian: the derivative
// at the colours held, less its part in the span of the colours' design; it drops only a term
// proportional to the residuals); h_i is taken at the fit's start and held. On a smear longer than a quarter radius,
// once the body's shading is learnt (body_shading.hpp), the body's term is c_i·S_i·F_k instead
// (no h_i: S_i holds the shading):
// S_i its mean relative colour over the part of it that passed over the sample, evaluated at the
// fit's start and held through the solve (each sample's mean shading basis is taken once there,
// and S_i under any lamp follows from it: BodyShading::FromBasis). The shading is read as lit by a lamp at a finite
// distance (BodyShading::LitFrom: a lamp a metre away is seen from the body in another direction
// once it has crossed the apparatus, and a shading lit from the wrong side pulls the centre
// along a long smear): before the solve, the lamp's inverse distance κ is fitted at
// the fit's start to the inlier rays with the centre held (one Gauss–Newton step from the
// request's κ, prior σ 0.5 /m), and the centre then solved with S_i from there. So the channel in
// which the fit sees the edge is, ray by ray, the colour difference between the body's limb and
// what lies behind it: a body as grey as the table but of another hue, or a table with grain,
// costs nothing. Where the background is not yet known at every sample of a ray (the body rested
// there since the first frame) the ray's background is a constant B_k solved the same way. A
// painted band, a highlight, a seam, the shadow: such a ray's samples do not follow one limb
// colour, its misfit is large, and a Cauchy loss per ray (scale: 4 times the expected χ² of a good
// ray) gives it no say.
//
// Parameters (smeared_outline.hpp's order): the centre (x, z) at the reference time, the smear D
// over the exposure, a uniform edge shift b. Priors: b ~ N(0, 0.3 px), D ~ N(D_pred, σ_D). The
// path's bend over the exposure (the motion's acceleration) is the caller's prediction, held.
//
// Accuracy: see ball_tracker.hpp. Cost: at most rays × samples × (pieces + 1) outline evaluations
// per Jacobian; at most FitRequest::iterations Ceres iterations per pass; one pass where the
// model measured the previous frame (ball_tracker.cpp, MeasureNear), else two or more. Ceres
// solves each ray as 6 rows (reduced_rows.hpp).
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <opencv2/core.hpp>

#include "vision/camera.hpp"
#include "background_model.hpp"
#include "smeared_outline.hpp"

namespace uphill::internal {

struct OutlineGeometry {
  SceneCalibration cal;
  Eigen::Matrix3d to_apparatus;  // camera -> apparatus rotation
  double a = 0, s = 1;           // body radius across, y scaling
  Eigen::Vector3d eye, eye_s;    // camera centre, and scaled
  double sigma_px = 0.7;         // point spread
  const cv::Mat* occluder = nullptr;  // CV_8U frame-size mask of hidden pixels
  const BodyShading* shading = nullptr;  // the body's appearance, once learnt (may be null)

  // Tangent points of the body centred at (x, 0, z), apparatus frame (n of them).
  std::vector<Eigen::Vector3d> OutlinePoints(double x, double z, int n) const;
  Eigen::Vector2d Project(double x, double z) const;
  double PxPerRad(double x, double z) const;
};

// The centre held near the line z = z0 + slope·(x − x0) (the path's tangent at x0) by a prior of
// σ sigma across it, m: the fit the tracker compares with a free one where a fit lies off the
// calibrated path (tracker_measure.cpp, HeldOnPath).
struct PathHold {
  double x0 = 0, z0 = 0, slope = 0, sigma = 0;
};

struct FitRequest {
  Eigen::Vector2d centre;               // (x, z) at the reference time, m
  Eigen::Vector2d smear = {0, 0};        // D predicted, m
  double smear_sigma = 0;               // σ_D, m (per component)
  Eigen::Vector2d bend = {0, 0};        // A = ½·a·E² (smeared_outline.hpp), m: held, not fitted
  Eigen::Vector2d velocity = {0, 0};    // m/s, for the rolling shutter's row delays
  double row_delay = 0;                 // s per row (readout / rows); 0: global shutter
  bool estimate_row_delay = false;      // true: estimate the row delay (FitOutcome::row_delay)
  double reference_row = 0;             // the row whose time is the reference
  double half_width_px = 6;             // uncertainty of the prediction along each ray
  int rays = 64;
  double noise = 0.01;                  // expected RMS of a sample's residual, linear units
  bool fit_edge_shift = true;           // false: b held at 0 (the tracker's passes that place the centre)
  double light_inverse_distance = 0;    // 1/m: the lamp's, prior mean (BodyShading::LitFrom)
  bool fit_light = true;                // false: held at its prior mean (a first pass)
  // false: no limb profile (h_i·G_k above): the search for a body found anew, where its freedom
  // lets a patch of the table fit an outline as well as the body does.
  bool limb_profile = true;
  // Ceres iterations at most. With Kaufman's Jacobian the step shrinks about four-fold per
  // iteration: from a coarse search 3 (more add nothing; fewer can stop on a wrong place under a
  // rolling shutter's shear); a narrow pass after a coarse search in 2; a
  // pass started within half a pixel or so, at a fit of the same frame or a checked prediction,
  // in 1 (ball_tracker.cpp).
  int iterations = 3;
  // Set: the centre held near the path's tangent line (PathHold).
  std::optional<PathHold> path;
};

// The picture a fit reads: a whole frame (origin 0, 0) or a window of one kept for a later refit,
// and that frame's exposure gain (background_model.hpp).
struct FrameView {
  const cv::Mat& bgr;  // 8-bit BGR
  cv::Point origin;    // frame pixel of bgr's (0, 0)
  double gain = 1;
};

struct FitOutcome {
  bool ok = false;
  std::array<double, kSmearParameters> p{};  // as SmearParameter
  int rays_tried = 0, rays_fitted = 0, inliers = 0;
  int rays_without_background = 0;  // rays where the background was not yet known
  double misfit = 0;    // RMS of the inlier rays' residuals in units of `noise`
  double contrast = 0;  // median |F − B| of the inliers, linear units
  double noise = 0;     // RMS residual of the inlier rays, linear units (for the next frame)
  double light_inverse_distance = 0;  // 1/m: fitted on a shaded smear, else the prior's
  // With FitRequest::estimate_row_delay: the row delay the inlier rays prefer (s per row), every
  // parameter free (one Gauss–Newton step from the fit at the request's delay), and its standard
  // error; row_delay_sigma 0: not estimated.
  double row_delay = 0, row_delay_sigma = 0;
  // The centre's move in the image at the solve's last successful iteration, px: how far from
  // settled a solve stopped by its cap of iterations was (0: no step taken).
  double last_step_px = 0;
  double ray_cost = 0;  // the rays' robust cost at the solution (Ceres' ½Σρ, residuals in units of the noise)
};

FitOutcome FitOutline(const OutlineGeometry& geometry, const FrameView& view, const BackgroundModel& background,
                      const FitRequest& request);

}  // namespace uphill::internal
