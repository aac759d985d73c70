// The body's silhouette smeared over an exposure: the fraction of a pixel's exposure during which
// its viewing ray meets the body, blurred by the optics' point spread. The tracker fits this
// model to the pixels across the outline (ball_tracker.cpp), so that a motion blur of several
// radii is measured rather than suffered.
//
// Geometry (ball_tracker.hpp): in the space where y is scaled by s = a/b the body is a sphere of
// radius a centred at C = (x, 0, z); a viewing direction d (unit, scaled space, from the camera
// centre O) meets it iff the angle θ(d, C − O) is below the half angle β = asin(a/|C − O|). The
// signed distance of d from the outline, in pixels, is δ = (θ − β)·p − b (p pixels per radian,
// b a uniform outward shift of the edges in pixels, a fit parameter; positive outside).
//
// Motion over the exposure: C(τ) = C_ray + D·τ + A·τ² for τ ∈ [−½, ½] (τ the fraction of the
// exposure, D the displacement of the centre during the exposure, C_ray the centre at the
// mid-exposure of the ray's rows: with a rolling shutter each row has its own exposure window, and
// the caller shifts C_ray by the velocity times the row's delay; within one ray the delay is taken
// constant). A = ½·a·E² is the bend of a path accelerated by a over the exposure E, given by the
// caller (not fitted): a ball rolling down steep rails gains speed during a long exposure, so it
// spends longer near the start of its smear than near the end, and a straight smear (A = 0) fitted
// to it puts the centre ahead of the mid-exposure by a fraction of A (0.2 px on a 3-radius blur).
//
// Coverage: c(d) = ∫_{−½}^{½} Φ(−δ(d, τ)/σ) dτ, σ the point spread (px, Gaussian across the
// edge), Φ the normal CDF. Computed by splitting [−½, ½] into M equal pieces on which δ is taken
// linear in τ; on each piece the integral of Φ is exact: the mean of Φ(u) over u linear from u0
// to u1 is (Ψ(u1) − Ψ(u0))/(u1 − u0), Ψ(u) = u·Φ(u) + φ(u). M = 1 is exact for a ray along the
// motion; across it δ(τ) bends where the smeared outline turns, and the error of the linear pieces
// is about (blur/M)²/(16·radius) px of edge position: SmearPieces picks M so that this stays below
// 0.02 px. Without motion (D = 0) c = Φ(−δ/σ), the soft edge of a sharp outline.
// Derivatives with respect to (x, z, D_x, D_z, b) are analytic: ∂θ/∂v = −(d − cosθ·ŵ)/(|v| sinθ),
// ∂β/∂v = −tanβ/|v|·ŵ, v = C − O, ŵ = v/|v|; accurate to rounding.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "body_shading.hpp"

namespace uphill::internal {

// The fit parameters of one frame, in this order.
enum SmearParameter { kCentreX, kCentreZ, kSmearX, kSmearZ, kEdgeShift, kSmearParameters };
using SmearGradient = std::array<double, kSmearParameters>;

struct SmearedBody {
  double a = 0;                                   // m, radius of the scaled sphere
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();  // camera centre, scaled space
  double px_per_rad = 1;                          // pixels per radian near the body
  double sigma_px = 0.7;                          // point spread across the edge, px
  const BodyShading* shading = nullptr;           // the body's appearance (ready), or none
};

// Pieces M for a blur of `blur_px` on a body of `radius_px` (see the header), at most kMostPieces.
constexpr int kMostPieces = 32;
int SmearPieces(double blur_px, double radius_px);

// The nodes of one exposure window: the body at τ_n = −½ + n/M, n = 0..M.
class SmearNodes {
 public:
  // params: (x, z, D_x, D_z, b) as SmearParameter; offset: added to the centre's (x, z) (the
  // rolling shutter's shift of this ray's rows); bend: A of the header, m; pieces: 1 to
  // kMostPieces (clamped).
  SmearNodes(const SmearedBody& body, const double* params, const Eigen::Vector2d& offset, int pieces,
             const Eigen::Vector2d& bend = Eigen::Vector2d::Zero());

  // The nodes of a window between two others of the same body, parameters and pieces that differ
  // only in their offset (a rolling shutter's rows), at the offset a + t·(b − a), t in [0, 1]: each
  // node's quantities interpolated linearly. They are smooth in the offset, so the error is of
  // second order: for offsets 1 mm apart at 0.6 m, below 4e-7 rad (1e-3 px at 2000 px per rad).
  // The reach (a bound) sums, piece by piece, the larger of the two ends' steps with 1e-3 to
  // spare: a step between them exceeds both by a second-order share, (span/distance)²/8, below
  // 1e-4 for offsets up to 2 cm apart at 0.6 m.
  SmearNodes(const SmearNodes& a, const SmearNodes& b, double t);

  // Coverage of the unit direction d (scaled space), and its gradient when grad != nullptr.
  // shade (when not null, and the body has a shading): the mean of the shading's basis over the
  // part of the body that passed over d (BodyShading::LearntBasisAt), the average over the nodes
  // weighted by their coverage Φ (trapezoidal in τ); zero where the body does not reach d.
  // BodyShading::FromBasis turns it into the body's mean relative colour there under any light.
  // Its derivatives are not given: it changes slowly with the parameters next to the coverage.
  double Coverage(const Eigen::Vector3d& d, SmearGradient* grad, BodyShading::Basis* shade = nullptr) const;

  // The signed distance δ (px) of d from the outline at the window's middle (τ = 0).
  double DistanceAtMiddle(const Eigen::Vector3d& d) const;

 private:
  struct Node {
    Eigen::Vector3d w;  // unit direction of C(τ) − O
    double norm, beta, tan_beta, tau;
  };
  const SmearedBody& body_;
  double shift_;
  // In place rather than on the heap: a rolling shutter builds nodes for nearly every sample.
  int count_ = 0;
  std::array<Node, kMostPieces + 1> nodes_;
  // px, per node: a bound of |δ_n − δ_0| for every direction, summed over the pieces (apart from
  // the nodes: Coverage scans it).
  std::array<double, kMostPieces + 1> reach_;
};

}  // namespace uphill::internal
