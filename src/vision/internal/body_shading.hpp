// The body's shading, learnt from frames where it rests sharp, for the smear model
// (smeared_outline.hpp).
//
// Why: along a smear of several radii a pixel sees the mean colour of the part of the body that
// passed over it: the limb for a pixel the body grazed, the parts deeper in for one it covered
// longer. A body lit from above is brighter on top, so that mean drifts along each ray across the
// smear, and a model that takes one limb colour per ray moves the fitted edge to absorb the drift
// (tests/vision_track_test.cpp, a matte shaded ball smeared over up to 3 radii: 0.39 px RMS with
// one limb colour per ray, 0.05 px with this shading turned to the light frame by frame).
//
// Model: the colour of a surface point is a function of its normal n alone (in the apparatus
// frame): the light stands still while the ball rolls, and a ball of one paint looks the same
// wherever it has turned to. Lambertian shading under distant lighting is, to within a few per
// cent, a quadratic in n (Ramamoorthi & Hanrahan 2001: the first nine spherical harmonics), so
// the shading is that quadratic, per channel, fitted to the sharp views: 1, n_x, n_y, n_z,
// n_x·n_y, n_y·n_z, n_x·n_z, n_x² − n_y², 3n_z² − 1. The normal rather than the place on the disc
// keeps the shading right as the ball moves across the picture and the camera sees it from
// another side. The views are sampled within 0.8 of the radius (beyond, the point spread mixes
// body and background); directions further out read the normal at 0.8 in the same direction,
// not an extrapolation. Values below 0.02 read 0.02.
//
// Robust fit: samples more than 2 robust deviations brighter than the fit (a highlight only adds
// light) or 3.5 darker are left out, eight times over. The shading is used (ready()) only where
// the quadratic explains at least 85 % of the samples to 8 % RMS of the body's colour: a strong
// highlight (it moves with the viewing direction, so it is not a function of the normal) or a
// pattern that turns with the body (a painted band) fails that, and the smear model then keeps
// one colour per ray. Measured: a matte ball 95 % of the samples at 1.2 %; the ray-traced ball of
// `uphill bench track` 94 % at 7 %; the synthetic glossy ball 77 % (not used).
//
// The light is not at infinity: a lamp a metre above the apparatus is seen from the body in
// directions tens of degrees apart as it rolls across (the ray-traced fast clips: 22°). The smear
// model reads the shading as lit by a lamp overhead at a finite distance (LitFrom): at 1/κ above
// where the shading was learnt, seen from the body displaced by ΔC in the direction
// ℓ' = (ẑ − κ·ΔC)/|ẑ − κ·ΔC|, so the shading is turned by the rotation that takes ẑ to ℓ'
// (Turned). κ is fitted frame by frame to the smear itself (outline_fit.hpp) and carried to the
// next frame: one number for the clip's geometry. Overhead, because labs are lit from the ceiling
// and the views cannot tell the lamp's direction (they show only the half of the body that faces
// the camera, where the shading's constant and its rise toward the camera trade off). Measured on
// the ray-traced fast clips, lit by a soft box above and a fill light by the camera: a free turn
// (three angles per frame) drifted about the vertical by up to 0.9 rad, absorbing what the shading
// does not model (the highlight, reflections), and pushed the centre of the 3-radius smears 0.17
// px across the path on average (RMS 0.33 px); with the overhead lamp, 0.09 px (RMS 0.26 px), the
// lamp fitted at 0.6–0.7 m (truly 0.8 m above the ball, and the fill light's turn is folded in).
//
// Values are relative: each view divided by its mean over the disc, channel by channel, so that
// the body's colour F of each ray of the smear model scales them (gain, flicker, the ray's own
// light).
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace uphill::internal {

struct OutlineGeometry;

class BodyShading {
 public:
  static constexpr int kViews = 4;  // views fitted before the shading is used

  using Coefficients = Eigen::Matrix<double, 9, 3>;  // rows: the basis above; columns: B, G, R

  // s: the y scaling of the scaled space (smeared_outline.hpp), a/b.
  explicit BodyShading(double s) : s_(s) {}
  // A shading given by its coefficients, learnt with the body centred at `learnt_at` (apparatus
  // frame, m), ready at once (a test's known shading).
  BodyShading(double s, const Coefficients& coefficients, const Eigen::Vector3d& learnt_at = Eigen::Vector3d::Zero())
      : s_(s), ready_(true), coefficients_(coefficients), learnt_at_(learnt_at), colours_(coefficients.transpose()) {}

  // One sharp view of the body resting with its centre at (x, 0, z) in `bgr` (8-bit BGR, `table`
  // its linear light). Views after kViews are ignored; the fit is made at the kViews-th.
  void Learn(const cv::Mat& bgr, const std::array<float, 256>& table, const OutlineGeometry& geometry, double x,
             double z);

  // Learnt, and the body's colour is a function of its normal (no pattern).
  bool ready() const { return ready_; }

  // The relative colour (B, G, R; about 1) seen along the unit direction d from the eye of the
  // body of radius a centred at v from the eye (scaled space); a direction that misses the body
  // reads its outline's nearest point. FromBasis(LearntBasisAt(d, v, a)).
  cv::Vec3d At(const Eigen::Vector3d& d, const Eigen::Vector3d& v, double a) const;

  // The quadratic basis (see the header) at the normal that At reads, in the frame the shading
  // was learnt in (before any turn of the light). The space of quadratics on the sphere is closed
  // under rotation, so under any light the colour is linear in this basis: a mean of bases over
  // many surface points (a smear's, smeared_outline.hpp) gives their mean colour under every
  // light through FromBasis, without visiting the points again.
  using Basis = Eigen::Matrix<double, 9, 1>;
  Basis LearntBasisAt(const Eigen::Vector3d& d, const Eigen::Vector3d& v, double a) const;

  // The colour of a basis (or of a mean of bases) under this shading's light, each channel at
  // least 0.02 (a quadratic may dip below zero where the views were darkest); a zero basis (no
  // surface point) reads 1. Accurate to rounding: the turn is applied to the coefficients as the
  // 9 × 9 matrix that maps the basis at a normal to the basis at the turned normal. For a mean of
  // bases the floor applies to the mean colour: it equals the mean of the points' colours where
  // none of them falls below the floor.
  cv::Vec3d FromBasis(const Basis& basis) const;

  // This shading with the light turned by the rotation vector omega (apparatus frame, rad): the
  // colour at normal n is the learnt colour at R(omega)ᵀ·n. Lit by a lamp a metre away, a body
  // that crosses the apparatus sees its light from directions tens of degrees apart.
  BodyShading Turned(const Eigen::Vector3d& omega) const;

  // This shading for the body centred at `centre` (apparatus frame, m) under a lamp at
  // 1/inverse_distance (m) above where it was learnt (see the header); inverse_distance 0: a light
  // at infinity, the shading as learnt.
  BodyShading LitFrom(const Eigen::Vector3d& centre, double inverse_distance) const;

  // Where the body was centred in the views (their mean; apparatus frame, m).
  const Eigen::Vector3d& learnt_at() const { return learnt_at_; }

  // The RMS of the fit's inliers, relative (for the tests and the decision to use it).
  double misfit() const { return misfit_; }

 private:
  static Basis OfNormal(const Eigen::Vector3d& n);


  double s_;
  int views_ = 0;
  bool ready_ = false;
  double misfit_ = 0;
  cv::Vec3d colour_ = cv::Vec3d(0, 0, 0);  // the views' mean colour, linear
  std::vector<std::pair<Basis, cv::Vec3d>> samples_;  // (basis at the normal, relative colour)
  Coefficients coefficients_ = Coefficients::Zero();
  Eigen::Vector3d learnt_at_ = Eigen::Vector3d::Zero();
  // The coefficients under the turned light (Turned), transposed: colour = colours_·basis.
  Eigen::Matrix<double, 3, 9> colours_ = Eigen::Matrix<double, 3, 9>::Zero();
};

}  // namespace uphill::internal
