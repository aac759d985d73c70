#include "outline_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "model/solver_logs.hpp"
#include "reduced_rows.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kEdgeShiftPriorPx = 0.3;
// σ of the background's factor along a ray (its level and its tilt): the body's soft shadow and
// uneven light. A factor free to tilt along the ray takes up part of an edge's position: at 5 %
// the fits' least-squares minima on the ray-traced clips lay about 0.07 px further from the truth
// (docs/track.md, "The fit's Jacobian").
constexpr double kShadowPrior = 0.01;
constexpr double kRayLossFactor = 1.5;  // Cauchy scale: this many times a good ray's χ²
// A smear longer than this many radii is fitted with the body's shading (body_shading.hpp).
constexpr double kShadedSmear = 0.25;
// The lamp's inverse distance in a frame (BodyShading::LitFrom): σ of its prior about the previous
// frame's, 1/m (a lamp a metre or two away; the first frames, where the body has barely moved,
// leave it at its prior), and the step of its numerical derivative.
constexpr double kLightPrior = 0.5;
constexpr double kLightStep = 0.02;
constexpr double kSharedRows = 0.5;  // a rolling shutter's ray spanning fewer rows shares one window
// Samples a smear's ramp along a ray is fitted at: on the fast ray-traced clips 16 measure as the
// window's 41 did (fast-360-30 0.256 px, against 0.255) in two thirds of the time; 8 to 12 move
// the painted spheroid's clip from 0.26 to 0.28-0.29 px.
constexpr double kRampSamples = 16;
// The least step between a window's samples, px. A sample is the bilinear interpolation of the
// four pixels around it, so samples half a pixel apart share most of their pixels and add little
// but time: on the ray-traced clips a step of 1 px measures as 0.5 px did (fast-360-30 0.237 px
// against 0.240, spheroid-band 0.248 against 0.250, isoluminant 0.130 against 0.132) in two
// thirds of the model's time. A painted band's inner edge is looked for at steps up to 1 px.
constexpr double kLeastStep = 1.0;

struct RaySamples {
  // A rolling shutter: each sample's row − the reference row (empty: a global shutter), the
  // velocity V (m/s) and the rows' delay δ (s per row); sample i sees the body shifted by V·Δrow·δ.
  std::vector<double> rows;
  Vector2d velocity = Vector2d::Zero();
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
  Vector2d bend = Vector2d::Zero();    // A of smeared_outline.hpp, m
  int pieces = 1;
  std::vector<Vector3d> dirs;          // unit, scaled space
  std::vector<double> along;           // position along the window, −1 … 1
  std::vector<cv::Vec3f> image, back;  // linear light; back empty: unknown (solved per ray)
};

// Keeps at most `most` of the samples, evenly spread over the window, its ends included.
void ThinOut(RaySamples* s, int most) {
  const int n = static_cast<int>(s->dirs.size());
  if (n <= most || most < 2) return;
  auto keep = [&](auto& v) {
    if (v.empty()) return;
    for (int j = 0; j < most; ++j) v[j] = v[static_cast<size_t>(std::lround(static_cast<double>(j) * (n - 1) / (most - 1)))];
    v.resize(most);
  };
  keep(s->dirs), keep(s->along), keep(s->image), keep(s->back), keep(s->rows);
}

// Per-ray linear least squares for what is not geometry, given the coverages c_i:
//   known background:  I_i = (1 − c_i)·(σ0 + σ1·t_i)·B_i + c_i·S_i·F   (σ: the body's shadow and
//                      the light's unevenness on this ray, weakly held at 1; F the body's colour)
//   unknown:           I_i = (1 − c_i)·(B0 + B1·t_i) + c_i·S_i·F         (per channel)
// t_i the sample's position along the window; S_i (per channel) the body's relative colour over
// the part of it that passed over the sample (smeared_outline.hpp, body_shading.hpp) on a shaded
// ray, else 1 (F is then the limb's colour). Returns the background term of each sample and F.
struct RayColours {
  std::vector<cv::Vec3d> back;  // (σ0 + σ1·t)·B, or B0 + B1·t, per sample
  cv::Vec3d body;
  bool ok = false;
  // The inverse of the solve's normal matrix (priors included): known background, over
  // (σ0, σ1, F); unknown, over (B0, B1, F) of each channel. ProjectedGram needs them.
  Eigen::Matrix<double, 5, 5> known_inverse;
  std::array<Eigen::Matrix3d, 3> unknown_inverse;
  // The design's own Gram matrix AᵀA (the normal matrix without the priors), likewise.
  Eigen::Matrix<double, 5, 5> known_design;
  std::array<Eigen::Matrix3d, 3> unknown_design;
};

RayColours SolveColours(const RaySamples& ray, const std::vector<double>& c, const std::vector<cv::Vec3d>& shade,
                        double noise) {
  RayColours out;
  const size_t n = c.size();
  out.back.resize(n);
  // The body's column of sample i in channel ch.
  const auto body = [&](size_t i, int ch) { return shade.empty() ? c[i] : c[i] * shade[i][ch]; };
  if (!ray.back.empty()) {
    Eigen::Matrix<double, 5, 5> a = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> y = Eigen::Matrix<double, 5, 1>::Zero();
    // The normal equations of the rows (u·B_ch, u·t·B_ch, k_ch at 2 + ch) of every sample and
    // channel, summed by their structure (u = 1 − c, t the position along the ray, k the body's
    // column).
    for (size_t i = 0; i < n; ++i) {
      const double u = 1 - c[i], t = ray.along[i];
      double bb = 0, bi = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const double b = ray.back[i][ch], image = ray.image[i][ch], k = body(i, ch);
        bb += b * b;
        bi += b * image;
        a(0, 2 + ch) += u * b * k;
        a(1, 2 + ch) += u * t * b * k;
        a(2 + ch, 2 + ch) += k * k;
        y(2 + ch) += k * image;
      }
      a(0, 0) += u * u * bb;
      a(0, 1) += u * u * t * bb;
      a(1, 1) += u * u * t * t * bb;
      y(0) += u * bi;
      y(1) += u * t * bi;
    }
    a(1, 0) = a(0, 1);
    for (int k = 2; k < 5; ++k) a(k, 0) = a(0, k), a(k, 1) = a(1, k);
    out.known_design = a;
    // σ = 1 ± 1 %: a soft shadow or uneven light, not a dark pattern taken for a shadowed table.
    const double w = (noise / kShadowPrior) * (noise / kShadowPrior);
    a(0, 0) += w, y(0) += w, a(1, 1) += w;
    const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(a);
    const Eigen::Matrix<double, 5, 1> x = ldlt.solve(y);
    if (!x.allFinite() || a.diagonal().tail<3>().minCoeff() < 1e-9) {
      for (size_t i = 0; i < n; ++i) out.back[i] = ray.back[i];
      return out;
    }
    for (size_t i = 0; i < n; ++i) out.back[i] = (x(0) + x(1) * ray.along[i]) * cv::Vec3d(ray.back[i]);
    out.body = cv::Vec3d(x(2), x(3), x(4));
    out.known_inverse = ldlt.solve(Eigen::Matrix<double, 5, 5>::Identity());
    out.ok = true;
    return out;
  }
  // Per channel: (B0, B1, F); the design is the same for the three unless the body is shaded.
  const int designs = shade.empty() ? 1 : 3;
  cv::Vec3d mean(0, 0, 0);
  for (size_t i = 0; i < n; ++i) mean += cv::Vec3d(ray.image[i]);
  mean /= static_cast<double>(n);
  for (int design = 0; design < designs; ++design) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d y = Eigen::Matrix3d::Zero();  // column per channel
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d row(1 - c[i], (1 - c[i]) * ray.along[i], body(i, design));
      a += row * row.transpose();
      for (int ch = 0; ch < 3; ++ch) y.col(ch) += row * static_cast<double>(ray.image[i][ch]);
    }
    const Eigen::Matrix3d without_priors = a;
    a(1, 1) += 1e-6 * (a(0, 0) + 1e-12);
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(a);
    const Eigen::Matrix3d x = ldlt.solve(y);
    if (!x.allFinite() || a(2, 2) < 1e-9 || ldlt.rcond() < 1e-9) {
      for (size_t i = 0; i < n; ++i) out.back[i] = mean;
      out.ok = false;
      return out;
    }
    for (int ch = design; ch < (designs == 1 ? 3 : design + 1); ++ch) {
      for (size_t i = 0; i < n; ++i) out.back[i][ch] = x(0, ch) + x(1, ch) * ray.along[i];
      out.body[ch] = x(2, ch);
      out.unknown_inverse[ch] = ldlt.solve(Eigen::Matrix3d::Identity());
      out.unknown_design[ch] = without_priors;
    }
  }
  out.ok = true;
  return out;
}

// The Gram matrix of [J r] for a ray (reduced_rows.hpp): r its residuals, 3 per sample, and J
// Kaufman's Jacobian of the variable projection: the columns ∂r/∂p at the colours held, J₀ (row
// (i, ch): k·∇c_i, k = −(F − B)/noise), less their part in the span of the colours' design A,
// J = J₀ − A·N⁻¹·Aᵀ·J₀ (N the colour solve's normal matrix, priors included). Without that
// projection a step of the centre is met by no change of the colours, where the colours do change
// with it, and Gauss–Newton converges only linearly (on fast-360-30 the step halved each
// iteration). J is not formed: with g = AᵀJ₀ and H = N⁻¹·g,
//   JᵀJ = J₀ᵀJ₀ − gᵀH − Hᵀg + Hᵀ·(AᵀA)·H   and   Jᵀr = J₀ᵀr − Hᵀ·(Aᵀr),
// sums over the samples in one pass. `gradient(i)`: ∇c_i over the P parameters (the smear's, or
// those and the rows' delay); `residuals`: the ray's r (Residuals).
template <int P, typename Gradient>
Eigen::Matrix<double, P + 1, P + 1> ProjectedGram(const RaySamples& ray, const std::vector<double>& c,
                                                  const Gradient& gradient, const std::vector<cv::Vec3d>& shade,
                                                  const RayColours& colours, const double* residuals, double inv_noise) {
  using VectorP = Eigen::Matrix<double, P, 1>;
  using MatrixP = Eigen::Matrix<double, P, P>;
  const size_t n = c.size();
  const bool known = !ray.back.empty();
  const auto body = [&](size_t i, int ch) { return shade.empty() ? c[i] : c[i] * shade[i][ch]; };
  MatrixP jj = MatrixP::Zero();                           // J₀ᵀJ₀
  Eigen::Matrix<double, 5, P> aj = decltype(aj)::Zero();  // AᵀJ₀ (known background: 5 colour unknowns)
  VectorP jr = VectorP::Zero();                           // J₀ᵀr
  Eigen::Matrix<double, 5, 1> ar = decltype(ar)::Zero();  // Aᵀr (known background)
  std::array<Eigen::Matrix<double, 3, P>, 3> aj_ch{};     // per channel (unknown background)
  std::array<Eigen::Vector3d, 3> ar_ch{};
  for (auto& m : aj_ch) m.setZero();
  for (auto& v : ar_ch) v.setZero();
  double rr = 0;
  for (size_t i = 0; i < n; ++i) {
    const VectorP g = gradient(i);
    const cv::Vec3d& B = colours.back[i];
    const cv::Vec3d F = !colours.ok ? B : shade.empty() ? colours.body : colours.body.mul(shade[i]);
    const double u = 1 - c[i], t = ray.along[i];
    double kk = 0, kr = 0, bk = 0, br = 0;
    double body_k[3];
    for (int ch = 0; ch < 3; ++ch) {
      const double r = residuals[3 * i + ch], k = -(F[ch] - B[ch]) * inv_noise;
      kk += k * k, kr += k * r, rr += r * r;
      if (!colours.ok) continue;
      const double a_body = body(i, ch);
      if (known) {
        const double b = ray.back[i][ch];
        bk += b * k, br += b * r;
        body_k[ch] = a_body * k;
        ar(2 + ch) += a_body * r;
      } else {
        const double w[3] = {u * k, u * t * k, a_body * k};
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < P; ++b) aj_ch[ch](a, b) += w[a] * g(b);
        ar_ch[ch] += Eigen::Vector3d(u, u * t, a_body) * r;
      }
    }
    // By hand: Eigen's rank updates do not unroll at this size, and this loop is the pass.
    for (int a = 0; a < P; ++a) {
      const double kg = kk * g(a);
      for (int b = a; b < P; ++b) jj(a, b) += kg * g(b);
      jr(a) += kr * g(a);
    }
    if (colours.ok && known) {
      const double w[5] = {u * bk, u * t * bk, body_k[0], body_k[1], body_k[2]};
      for (int a = 0; a < 5; ++a)
        for (int b = 0; b < P; ++b) aj(a, b) += w[a] * g(b);
      ar(0) += u * br, ar(1) += u * t * br;
    }
  }
  for (int a = 0; a < P; ++a)
    for (int b = 0; b < a; ++b) jj(a, b) = jj(b, a);
  if (colours.ok && known) {
    const Eigen::Matrix<double, 5, P> h = colours.known_inverse * aj;
    jj += -aj.transpose() * h - h.transpose() * aj + h.transpose() * colours.known_design * h;
    jr -= h.transpose() * ar;
  } else if (colours.ok) {
    for (int ch = 0; ch < 3; ++ch) {
      const Eigen::Matrix<double, 3, P> h = colours.unknown_inverse[ch] * aj_ch[ch];
      jj += -aj_ch[ch].transpose() * h - h.transpose() * aj_ch[ch] + h.transpose() * colours.unknown_design[ch] * h;
      jr -= h.transpose() * ar_ch[ch];
    }
  }
  Eigen::Matrix<double, P + 1, P + 1> gram;
  gram.template topLeftCorner<P, P>() = jj;
  gram.template topRightCorner<P, 1>() = jr;
  gram.template bottomLeftCorner<1, P>() = jr.transpose();
  gram(P, P) = rr;
  return gram;
}

using DelayGramMatrix = Eigen::Matrix<double, kSmearParameters + 2, kSmearParameters + 2>;

class RayCost : public ceres::CostFunction {
 public:
  // shaded: S_i from the body's shading at the parameters `start`, held through the solve (it
  // changes with the centre by a fraction of the shading's change over a radius, while the
  // coverage changes across the whole edge; and it costs as much as the coverage to evaluate).
  RayCost(const SmearedBody& body, RaySamples ray, double inv_noise, bool shaded, const double* start)
      : body_(body), ray_(std::move(ray)), inv_noise_(inv_noise) {
    set_num_residuals(kReduced);
    mutable_parameter_block_sizes()->push_back(kSmearParameters);
    if (shaded) {
      const size_t n = ray_.dirs.size();
      ray_.start_coverage.resize(n);
      ray_.start_gradient.resize(n);
      ray_.start_basis.resize(n);
      ForEachSample(start, [&](size_t i, const SmearNodes& nodes) {
        ray_.start_coverage[i] = nodes.Coverage(ray_.dirs[i], &ray_.start_gradient[i], &ray_.start_basis[i]);
      });
      std::copy(start, start + kSmearParameters, start_.begin());
      Shade();
    }
  }

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
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    if (!last_.At(p)) Reduce(p, &last_);
    std::copy(last_.residuals.begin(), last_.residuals.end(), residuals);
    if (jacobians && jacobians[0]) {
      std::copy(last_.jacobian.begin(), last_.jacobian.end(), jacobians[0]);
      // Ceres asks for the Jacobian only at a point it has moved to (or started from): where the
      // solve ends unless a later candidate is taken, and what Assess then reads.
      accepted_ = last_;
    }
    return true;
  }

  // |F − B| (linear units) and the ray's mean squared residual (units of the noise²) at p: from
  // the solve's last evaluations where it evaluated p, else computed.
  void Assess(const double* p, double* contrast, double* mean_square) const {
    const double count = 3.0 * static_cast<double>(ray_.dirs.size());
    for (const Reduced* known : {&last_, &accepted_})
      if (known->At(p)) {
        *contrast = known->contrast, *mean_square = known->sum_of_squares / count;
        return;
      }
    std::vector<double> r(3 * ray_.dirs.size());
    RayColours colours;
    Compute(p, ray_.shade, r.data(), &colours);
    double sum = 0;
    for (double v : r) sum += v * v;
    *contrast = Contrast(colours), *mean_square = sum / count;
  }

  size_t samples() const { return ray_.dirs.size(); }

  // The residuals at the fit's start (appended to r) under the body's light as it is now.
  void ResidualsAtStart(std::vector<double>* r) const {
    const size_t at = r->size();
    r->resize(at + 3 * ray_.dirs.size());
    Residuals(ray_.start_coverage, ShadeAtStart(), r->data() + at, nullptr);
  }

  // Keep each evaluation's coverages and gradients, for DelayGram at the solution.
  void KeepGradients() { keep_gradients_ = true; }

  // The Gram matrix of [J r] at p (reduced_rows.hpp) over the smear's parameters and, last, the
  // rows' delay (s per row). A change dδ of the delay moves the body that sample
  // i sees by V·row_i·dδ (row_i the row its nodes are taken at), so the delay's column is
  // row_i·(V·∇c_i), V·∇c_i along the centre's columns: as exact as those columns, the nodes'
  // interpolation between the ray's first and last rows being linear in the row.
  DelayGramMatrix DelayGram(const double* p) const {
    const size_t n = ray_.dirs.size();
    std::vector<double> c;
    std::vector<SmearGradient> grad;
    const Reduced* kept = nullptr;
    for (const Reduced* known : {&accepted_, &last_})
      if (!kept && known->At(p) && known->grad.size() == n) kept = known;
    if (kept) c = kept->c, grad = kept->grad;
    else CoverageAt(p, &c, &grad);
    std::vector<double> r(3 * n);
    RayColours colours;
    Residuals(c, ray_.shade, r.data(), &colours);
    const std::vector<double> rows = RowsSeen();
    const auto gradient = [&](size_t i) {
      Eigen::Matrix<double, kSmearParameters + 1, 1> g;
      for (int j = 0; j < kSmearParameters; ++j) g(j) = grad[i][j];
      const double along_motion = ray_.velocity.x() * grad[i][kCentreX] + ray_.velocity.y() * grad[i][kCentreZ];
      g(kSmearParameters) = rows[i] * along_motion;
      return g;
    };
    return ProjectedGram<kSmearParameters + 1>(ray_, c, gradient, ray_.shade, colours, r.data(), inv_noise_);
  }

 private:
  // visit(i, nodes) for every sample i with the smear's nodes it sees: the ray's, or with a
  // rolling shutter its own row's (the body moves by V·δ per row, 0.05 px at 2000 px/s and a
  // phone's 25 ms over 1080 rows), interpolated between the nodes of the ray's first and last
  // rows (SmearNodes' second constructor).
  template <typename Visit>
  void ForEachSample(const double* p, Visit visit) const {
    if (ray_.rows.empty()) {
      const SmearNodes nodes(body_, p, Vector2d::Zero(), ray_.pieces, ray_.bend);
      for (size_t i = 0; i < ray_.dirs.size(); ++i) visit(i, nodes);
      return;
    }
    const auto [lo, hi] = std::minmax_element(ray_.rows.begin(), ray_.rows.end());
    const auto window = [&](double row) {
      return SmearNodes(body_, p, ray_.velocity * (row * ray_.row_delay), ray_.pieces, ray_.bend);
    };
    if (*hi - *lo <= kSharedRows) {
      const SmearNodes nodes = window(0.5 * (*lo + *hi));
      for (size_t i = 0; i < ray_.dirs.size(); ++i) visit(i, nodes);
      return;
    }
    const SmearNodes first = window(*lo), last = window(*hi);
    for (size_t i = 0; i < ray_.dirs.size(); ++i) visit(i, SmearNodes(first, last, (ray_.rows[i] - *lo) / (*hi - *lo)));
  }

  // Every sample's coverage at p and its gradient: kept from the pass at the fit's start where p
  // is that start, else computed.
  void CoverageAt(const double* p, std::vector<double>* c, std::vector<SmearGradient>* grad) const {
    if (!ray_.start_gradient.empty() && std::equal(p, p + kSmearParameters, start_.begin())) {
      *c = ray_.start_coverage, *grad = ray_.start_gradient;
      return;
    }
    c->resize(ray_.dirs.size()), grad->resize(ray_.dirs.size());
    ForEachSample(p, [&](size_t i, const SmearNodes& nodes) { (*c)[i] = nodes.Coverage(ray_.dirs[i], &(*grad)[i]); });
  }

  // The row (relative to the reference row) whose nodes each sample is evaluated with, as
  // ForEachSample takes them: the rows' middle on a ray that shares one window, else its own.
  std::vector<double> RowsSeen() const {
    if (ray_.rows.empty()) return std::vector<double>(ray_.dirs.size(), 0.0);
    const auto [lo, hi] = std::minmax_element(ray_.rows.begin(), ray_.rows.end());
    if (*hi - *lo <= kSharedRows) return std::vector<double>(ray_.dirs.size(), 0.5 * (*lo + *hi));
    return ray_.rows;
  }

  // S_i of every sample from its basis at the fit's start, under the body's light as it is now.
  std::vector<cv::Vec3d> ShadeAtStart() const {
    std::vector<cv::Vec3d> shade(ray_.start_basis.size());
    for (size_t i = 0; i < shade.size(); ++i) shade[i] = body_.shading->FromBasis(ray_.start_basis[i]);
    return shade;
  }

  // The residuals at p with the shade S_i (empty: none), and the colours solved there (when not
  // null).
  void Compute(const double* p, const std::vector<cv::Vec3d>& shade, double* residuals, RayColours* solved) const {
    std::vector<double> c(ray_.dirs.size());
    ForEachSample(p, [&](size_t i, const SmearNodes& nodes) { c[i] = nodes.Coverage(ray_.dirs[i], nullptr); });
    Residuals(c, shade, residuals, solved);
  }

  // The residuals given the samples' coverages c, and the colours solved there (when not null).
  void Residuals(const std::vector<double>& c, const std::vector<cv::Vec3d>& shade, double* residuals,
                 RayColours* solved) const {
    const size_t n = ray_.dirs.size();
    RayColours colours = SolveColours(ray_, c, shade, 1.0 / inv_noise_);
    for (size_t i = 0; i < n; ++i) {
      const cv::Vec3d I = ray_.image[i];
      const cv::Vec3d& B = colours.back[i];
      const cv::Vec3d F = !colours.ok ? B : shade.empty() ? colours.body : colours.body.mul(shade[i]);
      for (int ch = 0; ch < 3; ++ch) residuals[3 * i + ch] = (I[ch] - B[ch] - c[i] * (F[ch] - B[ch])) * inv_noise_;
    }
    if (solved) *solved = std::move(colours);
  }

  const SmearedBody& body_;
  RaySamples ray_;
  double inv_noise_;
  // |F − B| of the colours solved at a point (linear units; 0 where the solve failed).
  static double Contrast(const RayColours& colours) {
    if (!colours.ok) return 0.0;
    cv::Vec3d mean_back(0, 0, 0);
    for (const cv::Vec3d& b : colours.back) mean_back += b;
    return cv::norm(colours.body - mean_back / static_cast<double>(colours.back.size()));
  }

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
  void Reduce(const double* p, Reduced* out) const {
    const size_t n = ray_.dirs.size();
    std::vector<double> c;
    std::vector<SmearGradient> grad;
    CoverageAt(p, &c, &grad);
    std::vector<double>& r = scratch_residuals_;
    r.resize(3 * n);
    RayColours colours;
    Residuals(c, ray_.shade, r.data(), &colours);
    const auto gradient = [&](size_t i) { return Eigen::Map<const Eigen::Matrix<double, kSmearParameters, 1>>(grad[i].data()); };
    const ReducedRows gram = ProjectedGram<kSmearParameters>(ray_, c, gradient, ray_.shade, colours, r.data(), inv_noise_);
    if (keep_gradients_) out->c = c, out->grad = grad;
    const ReducedRows factor = FactorGram(gram);
    for (int i = 0; i < kReduced; ++i) {
      out->residuals[i] = factor(i, kSmearParameters);
      for (int j = 0; j < kSmearParameters; ++j) out->jacobian[i * kSmearParameters + j] = factor(i, j);
    }
    out->sum_of_squares = gram(kSmearParameters, kSmearParameters);
    out->contrast = Contrast(colours);
    std::copy(p, p + kSmearParameters, out->p.begin());
    out->valid = true;
  }

  std::array<double, kSmearParameters> start_{};  // the fit's start, where the ray's start_* are
  bool keep_gradients_ = false;
  mutable Reduced last_, accepted_;
  mutable std::vector<double> scratch_residuals_;  // the full ray's, kept for their memory only
};

// The upper of the two middle values for an even count (internal::Median of track_series.hpp
// averages them), which is what the rays' inlier limit is set from.
double UpperMedian(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// A ray whose mean square (units of the noise²) is below this is an inlier.
double InlierLimit(const std::vector<double>& squares) { return kRayLossFactor * std::max(1.0, UpperMedian(squares)); }

// The lamp's inverse distance (BodyShading::LitFrom) that best explains the rays at the fit's
// start p, the centre held: one Gauss–Newton step from the prior mean over the rays that are
// inliers there, its derivative by a forward difference (each sample's shade from its basis at
// the start). *lit (the shading the rays read) is left lit by the result.
double FitLightDistance(const BodyShading& learnt, BodyShading* lit, const std::vector<RayCost*>& rays,
                        const double* p, double prior) {
  const Vector3d centre(p[kCentreX], 0, p[kCentreZ]);
  *lit = learnt.LitFrom(centre, prior);
  std::vector<std::vector<double>> at_prior(rays.size());
  std::vector<double> squares(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    rays[k]->ResidualsAtStart(&at_prior[k]);
    double sum = 0;
    for (double v : at_prior[k]) sum += v * v;
    squares[k] = sum / static_cast<double>(std::max<size_t>(1, at_prior[k].size()));
  }
  const double limit = InlierLimit(squares);
  std::vector<double> r0, r1;
  *lit = learnt.LitFrom(centre, prior + kLightStep);
  for (size_t k = 0; k < rays.size(); ++k)
    if (squares[k] < limit) {
      r0.insert(r0.end(), at_prior[k].begin(), at_prior[k].end());
      rays[k]->ResidualsAtStart(&r1);
    }
  const auto e0 = Eigen::Map<const Eigen::VectorXd>(r0.data(), static_cast<Eigen::Index>(r0.size()));
  const Eigen::VectorXd slope = (Eigen::Map<const Eigen::VectorXd>(r1.data(), static_cast<Eigen::Index>(r1.size())) - e0) / kLightStep;
  const double inv_prior = 1 / (kLightPrior * kLightPrior);
  double kappa = prior - slope.dot(e0) / (slope.squaredNorm() + inv_prior);
  if (!std::isfinite(kappa)) kappa = prior;
  *lit = learnt.LitFrom(centre, kappa);
  return kappa;
}

// σ_D of the smear's prior, m: the request's, or the smear held where it gives none.
double SmearPriorSigma(const FitRequest& q) { return q.smear_sigma > 0 ? q.smear_sigma : 1e-9; }

// The priors: b ~ N(0, 0.3 px), D ~ N(D_pred, σ_D).
struct PriorCost {
  Vector2d smear;
  double inv_smear_sigma;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = p[kEdgeShift] / kEdgeShiftPriorPx;
    r[1] = (p[kSmearX] - smear.x()) * inv_smear_sigma;
    r[2] = (p[kSmearZ] - smear.y()) * inv_smear_sigma;
    return true;
  }
};

// The rolling shutter's row delay (s per row) that the inlier rays prefer, every parameter free,
// and its standard error: one Gauss–Newton step in (p, δ) from the solution p at the request's
// delay, over the inlier rays' χ² and the priors. Its δ part is the least-squares delay of this
// frame to first order (the Schur complement of the smear's parameters: what the centre and the
// smear absorb of a wrong delay is given back), and the inverse's δ entry its variance (residuals
// in units of the noise). {0, 0} where the step is not defined.
std::pair<double, double> PreferredRowDelay(const std::vector<RayCost*>& costs, const std::vector<double>& squares,
                                            double limit, const double* p, const FitRequest& q) {
  DelayGramMatrix gram = DelayGramMatrix::Zero();
  for (size_t k = 0; k < costs.size(); ++k)
    if (squares[k] < limit) gram += costs[k]->DelayGram(p);
  constexpr int kDelay = kSmearParameters, kUnknowns = kSmearParameters + 1;
  using Matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;
  using Vector = Eigen::Matrix<double, kUnknowns, 1>;
  Matrix h = gram.topLeftCorner<kUnknowns, kUnknowns>();
  Vector g = gram.topRightCorner<kUnknowns, 1>();
  // The priors' rows (PriorCost): b/0.3 px and (D − D_pred)/σ_D; b held where it is.
  const double wb = 1 / (kEdgeShiftPriorPx * kEdgeShiftPriorPx);
  const double wd = 1 / std::pow(SmearPriorSigma(q), 2);
  h(kEdgeShift, kEdgeShift) += wb, g(kEdgeShift) += wb * p[kEdgeShift];
  h(kSmearX, kSmearX) += wd, g(kSmearX) += wd * (p[kSmearX] - q.smear.x());
  h(kSmearZ, kSmearZ) += wd, g(kSmearZ) += wd * (p[kSmearZ] - q.smear.y());
  if (!q.fit_edge_shift) {
    h.row(kEdgeShift).setZero(), h.col(kEdgeShift).setZero();
    h(kEdgeShift, kEdgeShift) = 1, g(kEdgeShift) = 0;
  }
  // Solved with the columns scaled to unit diagonal (metres, pixels and seconds per row).
  if (!(h.diagonal().array() > 0).all()) return {0, 0};
  const Vector d = h.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::LDLT<Matrix> ldlt(d.asDiagonal() * h * d.asDiagonal());
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return {0, 0};
  const Vector step = -(d.asDiagonal() * ldlt.solve(d.asDiagonal() * g));
  Vector unit = Vector::Zero();
  unit(kDelay) = 1;
  const double variance = d(kDelay) * d(kDelay) * ldlt.solve(unit)(kDelay);
  if (!std::isfinite(step(kDelay)) || !(variance > 0)) return {0, 0};
  return {q.row_delay + step(kDelay), std::sqrt(variance)};
}

bool InFront(const OutlineGeometry& g, double x, double z) {
  return (g.cal.pose.rotation * Vector3d(x, 0, z) + g.cal.pose.translation).z() > 2 * g.a &&
         (Vector3d(x, 0, z) - g.eye).norm() > 2 * std::max(g.a, g.a / g.s);
}

// The centre's move in the image at each successful iteration of a solve (the solver writes the
// parameters back every iteration): the last one says whether a solve stopped by its cap of
// iterations had settled.
class CentreSteps : public ceres::IterationCallback {
 public:
  CentreSteps(const OutlineGeometry& g, const double* params)
      : g_(g), params_(params), at_(g.Project(params[kCentreX], params[kCentreZ])) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0 && summary.step_is_successful) {
      const Vector2d now = g_.Project(params_[kCentreX], params_[kCentreZ]);
      last_px_ = (now - at_).norm();
      at_ = now;
    }
    return ceres::SOLVER_CONTINUE;
  }
  double last_px() const { return last_px_; }

 private:
  const OutlineGeometry& g_;
  const double* params_;
  Vector2d at_;
  double last_px_ = 0;
};

}  // namespace

std::vector<Vector3d> OutlineGeometry::OutlinePoints(double x, double z, int n) const {
  const Vector3d c(x, 0, z);
  const Vector3d axis = c - eye_s;
  const double dist = axis.norm();
  const Vector3d w = axis / dist;
  // A fixed reference direction keeps point k at the same place on the outline frame to frame.
  const Vector3d e1 = w.cross(Vector3d::UnitY()).normalized(), e2 = w.cross(e1);
  const double sin_b = std::min(1.0, a / dist), cos_b = std::sqrt(1 - sin_b * sin_b);
  std::vector<Vector3d> out;
  out.reserve(n);
  for (int k = 0; k < n; ++k) {
    const double phi = 2 * M_PI * k / n;
    const Vector3d ts = eye_s + (cos_b * w + sin_b * (std::cos(phi) * e1 + std::sin(phi) * e2)) * (dist * cos_b);
    out.emplace_back(ts.x(), ts.y() / s, ts.z());
  }
  return out;
}

Vector2d OutlineGeometry::Project(double x, double z) const {
  return ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(x, 0, z));
}

double OutlineGeometry::PxPerRad(double x, double z) const {
  return cal.camera.fx * (Vector3d(x, 0, z) - eye_s).norm() / (Vector3d(x, 0, z) - eye).norm();
}

FitOutcome FitOutline(const OutlineGeometry& g, const FrameView& view, const BackgroundModel& background,
                      const FitRequest& q) {
  const cv::Mat& bgr = view.bgr;
  const double gain = view.gain;
  // Where samples may be read: inside the frame and the view, a pixel in for the interpolation.
  const double left = std::max(1.0, view.origin.x + 1.0), top = std::max(1.0, view.origin.y + 1.0);
  const double right = std::min(g.cal.camera.width - 2.0, view.origin.x + bgr.cols - 2.0);
  const double bottom = std::min(g.cal.camera.height - 2.0, view.origin.y + bgr.rows - 2.0);
  FitOutcome out;
  out.light_inverse_distance = q.light_inverse_distance;
  const double x = q.centre.x(), z = q.centre.y();
  if (!InFront(g, x, z)) return out;
  const int n = q.rays;
  std::vector<Vector3d> points = g.OutlinePoints(x, z, n);
  points.emplace_back(x, 0, z);
  // The smear's ends, C(∓½) = C ∓ D/2 + A/4.
  points.emplace_back(x - 0.5 * q.smear.x() + 0.25 * q.bend.x(), 0, z - 0.5 * q.smear.y() + 0.25 * q.bend.y());
  points.emplace_back(x + 0.5 * q.smear.x() + 0.25 * q.bend.x(), 0, z + 0.5 * q.smear.y() + 0.25 * q.bend.y());
  const std::vector<Vector2d> image = ProjectApparatusPoints(g.cal.camera, g.cal.pose, points);
  const Vector2d centre = image[n], smear_px = image[n + 2] - image[n + 1];
  double radius_px = 0;
  for (int k = 0; k < n; ++k) radius_px += (image[k] - centre).norm() / n;
  const int pieces = SmearPieces(smear_px.norm(), radius_px);

  SmearedBody body;
  body.a = g.a;
  body.eye = g.eye_s;
  body.px_per_rad = g.PxPerRad(x, z);
  body.sigma_px = g.sigma_px;
  // The body's shading, where it is known and the smear is long enough for it to matter.
  const bool shaded = g.shading && g.shading->ready() && smear_px.norm() > kShadedSmear * radius_px;
  BodyShading lit = shaded ? g.shading->LitFrom(Vector3d(x, 0, z), q.light_inverse_distance) : BodyShading(1.0);
  if (shaded) body.shading = &lit;
  const bool fit_light = shaded && q.fit_light;  // the lamp's distance fitted, then the centre

  // Rays: windows and their three undistorted anchors (start, middle, end).
  struct Ray {
    Vector2d origin, dir;
    double s0, s1;
    double limb;  // a point surely inside the body (if the prediction holds), px along the ray
  };
  std::vector<Ray> rays;
  std::vector<Vector2d> anchors;
  const double margin_in = 1.5 + 2 * g.sigma_px, margin_out = 3.0 + 2 * g.sigma_px;
  for (int k = 0; k < n; ++k) {
    const Vector2d radial = image[k] - centre;
    const double r = radial.norm();
    if (r < 2) continue;
    Ray ray;
    ray.dir = radial / r;
    // The rolling shutter: the window follows the body's shift at the tangent point's row.
    const Vector2d offset = q.velocity * ((image[k].y() - q.reference_row) * q.row_delay);
    double shift = 0;
    if (q.row_delay != 0) shift = (g.Project(x + offset.x(), z + offset.y()) - centre).dot(ray.dir);
    const double along = 0.5 * std::abs(smear_px.dot(ray.dir));
    const double across = 0.5 * std::abs(smear_px.x() * ray.dir.y() - smear_px.y() * ray.dir.x());
    const double inward = std::min(0.85 * r, along + r - std::sqrt(std::max(0.0, r * r - across * across)));
    ray.s0 = std::max(-0.9 * r, -(inward + q.half_width_px + margin_in)) + shift;
    ray.s1 = along + q.half_width_px + margin_out + shift;
    ray.limb = -(inward + q.half_width_px + 1.5 * g.sigma_px + 0.3) + shift;
    ray.origin = image[k];
    // Inside the picture (with a pixel for the interpolation) and clear of the occluder.
    bool usable = true;
    for (double s : {ray.s0, 0.5 * (ray.s0 + ray.s1), ray.s1}) {
      const Vector2d p = ray.origin + s * ray.dir;
      usable = usable && p.x() >= left && p.y() >= top && p.x() < right && p.y() < bottom;
    }
    if (!usable) continue;
    rays.push_back(ray);
    for (double s : {ray.s0, 0.5 * (ray.s0 + ray.s1), ray.s1}) anchors.push_back(ray.origin + s * ray.dir);
  }
  out.rays_tried = static_cast<int>(rays.size());
  if (rays.size() < 8) return out;
  const std::vector<Vector2d> normalised = UndistortPixels(g.cal.camera, anchors);

  double params[kSmearParameters] = {x, z, q.smear.x(), q.smear.y(), 0.0};
  ceres::Problem problem;
  std::vector<RayCost*> costs;
  int without_background = 0;
  const double inv_noise = 1.0 / std::max(q.noise, 1e-4);
  const cv::Mat& occluder = *g.occluder;
  for (size_t k = 0; k < rays.size(); ++k) {
    const Ray& ray = rays[k];
    RaySamples samples;
    const bool rolling = q.row_delay > 0 || q.estimate_row_delay;
    samples.velocity = q.velocity;
    samples.row_delay = q.row_delay;
    samples.bend = q.bend;
    samples.pieces = pieces;
    const double length = ray.s1 - ray.s0;
    const double step = std::clamp(length / 40, kLeastStep, 3.0);
    const int count = static_cast<int>(std::ceil(length / step)) + 1;
    const Vector2d& na = normalised[3 * k];
    const Vector2d& nm = normalised[3 * k + 1];
    const Vector2d& nb = normalised[3 * k + 2];
    bool hidden = false, known = true;
    for (int i = 0; i < count && !hidden; ++i) {
      const double t = static_cast<double>(i) / (count - 1);
      const Vector2d p = ray.origin + (ray.s0 + t * length) * ray.dir;
      hidden = occluder.at<std::uint8_t>(static_cast<int>(p.y() + 0.5), static_cast<int>(p.x() + 0.5)) != 0;
      // Quadratic through the three undistorted anchors (the lens bends a 40 px segment by far
      // less than its curvature can show).
      const Vector2d m = na * ((1 - t) * (1 - 2 * t)) + nm * (4 * t * (1 - t)) + nb * (t * (2 * t - 1));
      Vector3d d = g.to_apparatus * Vector3d(m.x(), m.y(), 1.0);
      d.y() *= g.s;
      samples.dirs.push_back(d.normalized());
      samples.along.push_back(2 * t - 1);
      if (rolling) samples.rows.push_back(p.y() - q.reference_row);
      samples.image.push_back(SampleLinear(bgr, background.table(), p.x() - view.origin.x, p.y() - view.origin.y));
      if (known && background.Known(p.x(), p.y())) samples.back.push_back(background.At(p.x(), p.y()) * gain);
      else known = false;
    }
    if (hidden) {
      --out.rays_tried;  // hidden by a rail: not part of the visible outline
      continue;
    }
    if (!known) samples.back.clear(), ++without_background;
    // Inner edges are not outline edges: where the body's colour changes inside the limb (a
    // painted band, a dot, a seam), the window ends, so that the limb's colour is one colour.
    const int limb = static_cast<int>(std::lround((ray.limb - ray.s0) / step));
    if (step <= kLeastStep && limb >= 1 && limb + 1 < count) {
      const cv::Vec3f colour = 0.5f * (samples.image[limb] + samples.image[limb + 1]);
      const double threshold = std::max(0.25 * cv::norm(colour - samples.image.back()), 5 * q.noise);
      for (int j = limb - 1; j >= 0; --j)
        if (cv::norm(samples.image[j] - colour) > threshold) {
          const auto cut = [j](auto& v) {
            if (!v.empty()) v.erase(v.begin(), v.begin() + j + 1);
          };
          cut(samples.dirs), cut(samples.along), cut(samples.image), cut(samples.back), cut(samples.rows);
          break;
        }
    }
    // A smear's edge along this ray is a ramp as long as the smear's extent along it: the fit
    // reads it at kRampSamples samples (at most 3 px apart), not at the window's finer step, which
    // the band's edges above and the sharp edges across the motion need.
    const double fit_step = std::min(3.0, std::abs(smear_px.dot(ray.dir)) / kRampSamples);
    if (fit_step > step) ThinOut(&samples, static_cast<int>(std::ceil(length / fit_step)) + 1);
    const double loss_scale = std::sqrt(kRayLossFactor * 3.0 * samples.dirs.size());
    auto* cost = new RayCost(body, std::move(samples), inv_noise, shaded, params);
    if (q.estimate_row_delay) cost->KeepGradients();
    costs.push_back(cost);
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(loss_scale), params);
  }
  out.rays_fitted = static_cast<int>(costs.size());
  out.rays_without_background = without_background;
  if (costs.size() < 8) return out;
  const double sigma_d = SmearPriorSigma(q);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 3, kSmearParameters>(
                               new PriorCost{q.smear, 1.0 / sigma_d}),
                           nullptr, params);
  if (!q.fit_edge_shift) problem.SetManifold(params, new ceres::SubsetManifold(kSmearParameters, {kEdgeShift}));
  QuietSolverLogs();
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  // The request's cap (FitRequest::iterations). Each iteration costs a Jacobian of every sample.
  solver.max_num_iterations = std::max(1, q.iterations);
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  // Parameters are metres near 0.5 and pixels: 1e-7 of the centre is below 1e-4 px; the cost's
  // relative change 1e-7 is far below what the noise moves it.
  solver.function_tolerance = 1e-7;
  solver.parameter_tolerance = 1e-7;
  ceres::Solver::Summary summary;
  CentreSteps steps(g, params);
  solver.callbacks.push_back(&steps);
  solver.update_state_every_iteration = true;  // for CentreSteps
  // The shading learnt where the body rested, lit from where this frame sees the lamp at the
  // fit's start (a first pass's result, or the prediction where the model measured the frame
  // before): solving first and then once more from there measures the same on the ray-traced
  // clips, at a second solve's cost.
  if (fit_light) {
    out.light_inverse_distance = FitLightDistance(*g.shading, &lit, costs, params, q.light_inverse_distance);
    for (RayCost* cost : costs) cost->Shade();
  }
  ceres::Solve(solver, &problem, &summary);
  for (double v : params)
    if (!std::isfinite(v)) return out;
  if (!InFront(g, params[kCentreX], params[kCentreZ])) return out;

  std::vector<double> squares(costs.size()), contrasts(costs.size());
  for (size_t k = 0; k < costs.size(); ++k) costs[k]->Assess(params, &contrasts[k], &squares[k]);
  const double median = UpperMedian(squares);
  const double limit = InlierLimit(squares);
  double sum = 0;
  std::vector<double> inlier_contrasts;
  for (size_t k = 0; k < costs.size(); ++k)
    if (squares[k] < limit) {
      ++out.inliers;
      sum += squares[k];
      inlier_contrasts.push_back(contrasts[k]);
    }
  if (out.inliers == 0) return out;
  std::nth_element(inlier_contrasts.begin(), inlier_contrasts.begin() + inlier_contrasts.size() / 2,
                   inlier_contrasts.end());
  out.contrast = inlier_contrasts[inlier_contrasts.size() / 2];
  out.misfit = std::sqrt(sum / out.inliers);
  out.noise = q.noise * std::sqrt(median);
  std::copy(std::begin(params), std::end(params), out.p.begin());
  out.last_step_px = steps.last_px();
  if (q.estimate_row_delay) {
    const auto [delay, sigma] = PreferredRowDelay(costs, squares, limit, params, q);
    out.row_delay = delay, out.row_delay_sigma = sigma;
  }
  out.ok = true;
  return out;
}

}  // namespace uphill::internal
