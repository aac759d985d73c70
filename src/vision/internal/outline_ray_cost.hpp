// RayCost: the outline fit's residuals along one ray (outline_fit.cpp), as Ceres evaluates them:
// the samples of a window across the body's predicted outline, the smeared body's coverage of
// each (smeared_outline.hpp), the colours solved per ray by linear least squares, and the ray
// reduced to a few rows with the same normal equations (reduced_rows.hpp). Private to the fit.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "body_shading.hpp"
#include "outline_fit.hpp"
#include "reduced_rows.hpp"
#include "smeared_outline.hpp"

namespace uphill::internal {

inline constexpr double kEdgeShiftPriorPx = 0.3;
// σ of the background's factor along a ray (its level and its tilt): the body's soft shadow and
// uneven light. A factor free to tilt along the ray takes up part of an edge's position, so it is
// held tightly.
inline constexpr double kShadowPrior = 0.01;
// σ of the limb profile's amplitude G (RaySamples::limb_depth), linear units (0..1): held to a
// twentieth of the range, since a profile free to take a body's whole range of colours also takes
// a print's inner edge or a highlight inside the window for it. On 121 seen random scenes 0.3,
// 0.1 and 0.05 gained alike on plain bodies, and 0.05 cost the fewest printed ones.
inline constexpr double kLimbGradientPrior = 0.05;
inline constexpr double kRayLossFactor = 1.5;  // Cauchy scale: this many times a good ray's χ²
// A smear longer than this many radii is fitted with the body's shading (body_shading.hpp).
inline constexpr double kShadedSmear = 0.25;
// The lamp's inverse distance in a frame (BodyShading::LitFrom): σ of its prior about the previous
// frame's, 1/m (a lamp a metre or two away; the first frames, where the body has barely moved,
// leave it at its prior), and the step of its numerical derivative.
inline constexpr double kLightPrior = 0.5;
inline constexpr double kLightStep = 0.02;
inline constexpr double kSharedRows = 0.5;  // a rolling shutter's ray spanning fewer rows shares one window
// Samples a smear's ramp along a ray is fitted at: 16 resolve the ramp as well as the whole
// window's samples do, while fewer lose the inner edge of a painted band.
inline constexpr double kRampSamples = 16;
// The least step between a window's samples, px. A sample is the bilinear interpolation of the
// four pixels around it, so samples half a pixel apart share most of their pixels and add little
// but time. A painted band's inner edge is looked for at steps up to 1 px.
inline constexpr double kLeastStep = 1.0;

struct RaySamples {
  // A rolling shutter: each sample's row − the reference row (empty: a global shutter), the
  // velocity V (m/s) and the rows' delay δ (s per row); sample i sees the body shifted by V·Δrow·δ.
  std::vector<double> rows;
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  double row_delay = 0;
  // The body's relative colour over the part of it that passed over each sample (S_i below), at
  // the fit's starting point; empty: one colour per ray.
  std::vector<cv::Vec3d> shade;
  // On a shaded ray, each sample's coverage, its gradient and mean shading basis at the fit's
  // start (smeared_outline.hpp): S_i under any light follows from them without another pass over
  // the smear's nodes, and the solve's first evaluation, there, needs none either.
  std::vector<double> start_coverage;
  std::vector<SmearGradient> start_gradient;
  std::vector<BodyShading::Basis> start_basis;
  Eigen::Vector2d bend = Eigen::Vector2d::Zero();    // A of smeared_outline.hpp, m
  int pieces = 1;
  std::vector<Eigen::Vector3d> dirs;          // unit, scaled space
  std::vector<double> along;           // position along the window, −1 … 1
  std::vector<cv::Vec3f> image, back;  // linear light; back empty: unknown (solved per ray)
  // The limb's shading profile h_i = min(1, √(2·d_i/r)), d_i the sample's depth inside the
  // predicted outline and r the outline's radius, px (0 outside): near the limb the surface turns
  // toward the camera as √(2d/r), so a body's shading changes fastest right at its outline (a matte
  // body lit from the front is dark at the limb). Empty: none (a shaded ray, whose S_i holds it).
  std::vector<double> limb_depth;
};

// Keeps at most `most` of the samples, evenly spread over the window, its ends included.
void ThinOut(RaySamples* s, int most);

// The colours solved along a ray (outline_ray_cost.cpp).
struct RayColours;

using DelayGramMatrix = Eigen::Matrix<double, kSmearParameters + 2, kSmearParameters + 2>;

class RayCost : public ceres::CostFunction {
 public:
  // shaded: S_i from the body's shading at the parameters `start`, held through the solve (it
  // changes with the centre by a fraction of the shading's change over a radius, while the
  // coverage changes across the whole edge; and it costs as much as the coverage to evaluate).
  RayCost(const SmearedBody& body, RaySamples ray, double inv_noise, bool shaded, const double* start);

  // S_i at the fit's start under the body's light as it is now (the lamp fitted since).
  void Shade() {
    last_.valid = accepted_.valid = false;
    ray_.shade = ShadeAtStart();
  }

  // What Ceres sees of a ray: its 3 residuals per sample reduced to 6 rows with the same JᵀJ,
  // Jᵀr and |r|² (reduced_rows.hpp): the full ray's solve, Cauchy loss included, to rounding,
  // with the solver's own work that of 6 rows instead of ~100.
  //
  // Ceres evaluates a candidate's cost and, when it takes the step, the Jacobian at the same
  // point: so the Jacobian is computed with every cost and kept for that second call (the same
  // numbers, the coverage computed once).
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  // |F − B| (linear units) and the ray's mean squared residual (units of the noise²) at p: from
  // the solve's last evaluations where it evaluated p, else computed.
  void Assess(const double* p, double* contrast, double* mean_square) const;

  size_t samples() const { return ray_.dirs.size(); }

  // The residuals at the fit's start (appended to r) under the body's light as it is now.
  void ResidualsAtStart(std::vector<double>* r) const;

  // Keep each evaluation's coverages and gradients, for DelayGram at the solution.
  void KeepGradients() { keep_gradients_ = true; }

  // The Gram matrix of [J r] at p (reduced_rows.hpp) over the smear's parameters and, last, the
  // rows' delay (s per row). A change dδ of the delay moves the body that sample
  // i sees by V·row_i·dδ (row_i the row its nodes are taken at), so the delay's column is
  // row_i·(V·∇c_i), V·∇c_i along the centre's columns: as exact as those columns, the nodes'
  // interpolation between the ray's first and last rows being linear in the row.
  DelayGramMatrix DelayGram(const double* p) const;

 private:
  // visit(i, nodes) for every sample i with the smear's nodes it sees: the ray's, or with a
  // rolling shutter its own row's (the body moves by V·δ per row, 0.05 px at 2000 px/s and a
  // phone's 25 ms over 1080 rows), interpolated between the nodes of the ray's first and last
  // rows (SmearNodes' second constructor).
  template <typename Visit>
  void ForEachSample(const double* p, Visit visit) const;

  // Every sample's coverage at p and its gradient: kept from the pass at the fit's start where p
  // is that start, else computed.
  void CoverageAt(const double* p, std::vector<double>* c, std::vector<SmearGradient>* grad) const;

  // The row (relative to the reference row) whose nodes each sample is evaluated with, as
  // ForEachSample takes them: the rows' middle on a ray that shares one window, else its own.
  std::vector<double> RowsSeen() const;

  // S_i of every sample from its basis at the fit's start, under the body's light as it is now.
  std::vector<cv::Vec3d> ShadeAtStart() const;

  // The residuals at p with the shade S_i (empty: none), and the colours solved there (when not
  // null).
  void Compute(const double* p, const std::vector<cv::Vec3d>& shade, double* residuals, RayColours* solved) const;

  // The residuals given the samples' coverages c, and the colours solved there (when not null).
  void Residuals(const std::vector<double>& c, const std::vector<cv::Vec3d>& shade, double* residuals,
                 RayColours* solved) const;

  const SmearedBody& body_;
  RaySamples ray_;
  double inv_noise_;
  // |F − B| of the colours solved at a point (linear units; 0 where the solve failed).
  static double Contrast(const RayColours& colours);

  // A point Evaluate computed: the ray's reduced residuals r̃ and Jacobian J̃ (row-major), the
  // full residuals' sum of squares, and the contrast.
  static constexpr int kReduced = kSmearParameters + 1;
  static_assert(kReducedUnknowns == kSmearParameters);
  struct Reduced {
    bool valid = false;
    std::array<double, kSmearParameters> p{};
    std::array<double, kReduced> residuals{};
    std::array<double, kReduced * kSmearParameters> jacobian{};
    double sum_of_squares = 0, contrast = 0;
    std::vector<double> c;              // the coverages and their gradients (KeepGradients)
    std::vector<SmearGradient> grad;
    bool At(const double* q) const { return valid && std::equal(q, q + kSmearParameters, p.begin()); }
  };

  // The ray at p reduced to *out (see Evaluate).
  void Reduce(const double* p, Reduced* out) const;

  std::array<double, kSmearParameters> start_{};  // the fit's start, where the ray's start_* are
  bool keep_gradients_ = false;
  mutable Reduced last_, accepted_;
  mutable std::vector<double> scratch_residuals_;  // the full ray's, kept for their memory only
};

}  // namespace uphill::internal
