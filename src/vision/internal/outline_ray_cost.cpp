#include "outline_ray_cost.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace uphill::internal {

using Eigen::Vector2d;
using Eigen::Vector3d;

void ThinOut(RaySamples* s, int most) {
  const int n = static_cast<int>(s->dirs.size());
  if (n <= most || most < 2) return;
  auto keep = [&](auto& v) {
    if (v.empty()) return;
    for (int j = 0; j < most; ++j) v[j] = v[static_cast<size_t>(std::lround(static_cast<double>(j) * (n - 1) / (most - 1)))];
    v.resize(most);
  };
  keep(s->dirs), keep(s->along), keep(s->image), keep(s->back), keep(s->rows), keep(s->limb_depth);
}

// Per-ray linear least squares for what is not geometry, given the coverages c_i:
//   known background:  I_i = (1 − c_i)·(σ0 + σ1·t_i)·B_i + c_i·(S_i·F + h_i·G)   (σ: the body's
//                      shadow and the light's unevenness on this ray, weakly held at 1; F the
//                      body's colour)
//   unknown:           I_i = (1 − c_i)·(B0 + B1·t_i) + c_i·(S_i·F + h_i·G)         (per channel)
// t_i the sample's position along the window; S_i (per channel) the body's relative colour over
// the part of it that passed over the sample (smeared_outline.hpp, body_shading.hpp) on a shaded
// ray, else 1 (F is then the limb's colour); h_i the limb's shading profile (RaySamples::
// limb_depth, 0 on a shaded ray), G its amplitude, weakly held at 0. Returns the background term
// of each sample, F and G.
inline constexpr int kKnownColours = 8;  // σ0, σ1, F (3), G (3)
inline constexpr int kUnknownColours = 4;  // per channel: B0, B1, F, G
struct RayColours {
  std::vector<cv::Vec3d> back;  // (σ0 + σ1·t)·B, or B0 + B1·t, per sample
  cv::Vec3d body, limb_gradient;  // F and G
  bool ok = false;
  // The inverse of the solve's normal matrix (priors included): known background, over
  // (σ0, σ1, F, G); unknown, over (B0, B1, F, G) of each channel. ProjectedGram needs them.
  Eigen::Matrix<double, kKnownColours, kKnownColours> known_inverse;
  std::array<Eigen::Matrix4d, 3> unknown_inverse;
  // The design's own Gram matrix AᵀA (the normal matrix without the priors), likewise.
  Eigen::Matrix<double, kKnownColours, kKnownColours> known_design;
  std::array<Eigen::Matrix4d, 3> unknown_design;

  // The body's colour at sample i (F, or S_i·F, plus h_i·G), or the background where the solve
  // failed.
  cv::Vec3d BodyAt(const RaySamples& ray, const std::vector<cv::Vec3d>& shade, size_t i) const {
    if (!ok) return back[i];
    const cv::Vec3d f = shade.empty() ? body : body.mul(shade[i]);
    return ray.limb_depth.empty() ? f : f + ray.limb_depth[i] * limb_gradient;
  }
};

namespace {

RayColours SolveColours(const RaySamples& ray, const std::vector<double>& c, const std::vector<cv::Vec3d>& shade,
                        double noise) {
  RayColours out;
  const size_t n = c.size();
  out.back.resize(n);
  // The body's column of sample i in channel ch.
  const auto body = [&](size_t i, int ch) { return shade.empty() ? c[i] : c[i] * shade[i][ch]; };
  const auto limb = [&](size_t i) { return ray.limb_depth.empty() ? 0.0 : c[i] * ray.limb_depth[i]; };
  // G ~ N(0, kLimbGradientPrior): it has a say only where the samples ask for it.
  const double wg = (noise / kLimbGradientPrior) * (noise / kLimbGradientPrior);
  if (!ray.back.empty()) {
    constexpr int K = kKnownColours;
    Eigen::Matrix<double, K, K> a = Eigen::Matrix<double, K, K>::Zero();
    Eigen::Matrix<double, K, 1> y = Eigen::Matrix<double, K, 1>::Zero();
    // The normal equations of the rows (u·B_ch, u·t·B_ch, k_ch at 2 + ch, l at 5 + ch) of every
    // sample and channel, summed by their structure (u = 1 − c, t the position along the ray, k
    // the body's column, l the limb profile's).
    for (size_t i = 0; i < n; ++i) {
      const double u = 1 - c[i], t = ray.along[i], l = limb(i);
      double bb = 0, bi = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const double b = ray.back[i][ch], image = ray.image[i][ch], k = body(i, ch);
        bb += b * b;
        bi += b * image;
        a(0, 2 + ch) += u * b * k;
        a(1, 2 + ch) += u * t * b * k;
        a(2 + ch, 2 + ch) += k * k;
        y(2 + ch) += k * image;
        a(0, 5 + ch) += u * b * l;
        a(1, 5 + ch) += u * t * b * l;
        a(2 + ch, 5 + ch) += k * l;
        a(5 + ch, 5 + ch) += l * l;
        y(5 + ch) += l * image;
      }
      a(0, 0) += u * u * bb;
      a(0, 1) += u * u * t * bb;
      a(1, 1) += u * u * t * t * bb;
      y(0) += u * bi;
      y(1) += u * t * bi;
    }
    for (int r = 0; r < K; ++r)
      for (int col = 0; col < r; ++col) a(r, col) = a(col, r);
    out.known_design = a;
    // σ = 1 ± 1 %: a soft shadow or uneven light, not a dark pattern taken for a shadowed table.
    const double w = (noise / kShadowPrior) * (noise / kShadowPrior);
    a(0, 0) += w, y(0) += w, a(1, 1) += w;
    for (int ch = 0; ch < 3; ++ch) a(5 + ch, 5 + ch) += wg;
    const Eigen::LDLT<Eigen::Matrix<double, K, K>> ldlt(a);
    const Eigen::Matrix<double, K, 1> x = ldlt.solve(y);
    if (!x.allFinite() || a.diagonal().segment<3>(2).minCoeff() < 1e-9) {
      for (size_t i = 0; i < n; ++i) out.back[i] = ray.back[i];
      return out;
    }
    for (size_t i = 0; i < n; ++i) out.back[i] = (x(0) + x(1) * ray.along[i]) * cv::Vec3d(ray.back[i]);
    out.body = cv::Vec3d(x(2), x(3), x(4));
    out.limb_gradient = cv::Vec3d(x(5), x(6), x(7));
    out.known_inverse = ldlt.solve(Eigen::Matrix<double, K, K>::Identity());
    out.ok = true;
    return out;
  }
  // Per channel: (B0, B1, F, G); the design is the same for the three unless the body is shaded.
  const int designs = shade.empty() ? 1 : 3;
  cv::Vec3d mean(0, 0, 0);
  for (size_t i = 0; i < n; ++i) mean += cv::Vec3d(ray.image[i]);
  mean /= static_cast<double>(n);
  for (int design = 0; design < designs; ++design) {
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    Eigen::Matrix<double, 4, 3> y = Eigen::Matrix<double, 4, 3>::Zero();  // column per channel
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector4d row(1 - c[i], (1 - c[i]) * ray.along[i], body(i, design), limb(i));
      a += row * row.transpose();
      for (int ch = 0; ch < 3; ++ch) y.col(ch) += row * static_cast<double>(ray.image[i][ch]);
    }
    const Eigen::Matrix4d without_priors = a;
    a(1, 1) += 1e-6 * (a(0, 0) + 1e-12);
    a(3, 3) += wg;
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(a);
    const Eigen::Matrix<double, 4, 3> x = ldlt.solve(y);
    if (!x.allFinite() || a(2, 2) < 1e-9 || ldlt.rcond() < 1e-9) {
      for (size_t i = 0; i < n; ++i) out.back[i] = mean;
      out.ok = false;
      return out;
    }
    for (int ch = design; ch < (designs == 1 ? 3 : design + 1); ++ch) {
      for (size_t i = 0; i < n; ++i) out.back[i][ch] = x(0, ch) + x(1, ch) * ray.along[i];
      out.body[ch] = x(2, ch);
      out.limb_gradient[ch] = x(3, ch);
      out.unknown_inverse[ch] = ldlt.solve(Eigen::Matrix4d::Identity());
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
// with it, and Gauss–Newton converges only linearly (the step halves each
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
  const auto limb = [&](size_t i) { return ray.limb_depth.empty() ? 0.0 : c[i] * ray.limb_depth[i]; };
  constexpr int K = kKnownColours, U = kUnknownColours;
  MatrixP jj = MatrixP::Zero();                           // J₀ᵀJ₀
  Eigen::Matrix<double, K, P> aj = decltype(aj)::Zero();  // AᵀJ₀ (known background)
  VectorP jr = VectorP::Zero();                           // J₀ᵀr
  Eigen::Matrix<double, K, 1> ar = decltype(ar)::Zero();  // Aᵀr (known background)
  std::array<Eigen::Matrix<double, U, P>, 3> aj_ch{};     // per channel (unknown background)
  std::array<Eigen::Vector4d, 3> ar_ch{};
  for (auto& m : aj_ch) m.setZero();
  for (auto& v : ar_ch) v.setZero();
  double rr = 0;
  for (size_t i = 0; i < n; ++i) {
    const VectorP g = gradient(i);
    const cv::Vec3d& B = colours.back[i];
    const cv::Vec3d F = colours.BodyAt(ray, shade, i);
    const double u = 1 - c[i], t = ray.along[i], l = limb(i);
    double kk = 0, kr = 0, bk = 0, br = 0;
    double body_k[3], limb_k[3];
    for (int ch = 0; ch < 3; ++ch) {
      const double r = residuals[3 * i + ch], k = -(F[ch] - B[ch]) * inv_noise;
      kk += k * k, kr += k * r, rr += r * r;
      if (!colours.ok) continue;
      const double a_body = body(i, ch);
      if (known) {
        const double b = ray.back[i][ch];
        bk += b * k, br += b * r;
        body_k[ch] = a_body * k;
        limb_k[ch] = l * k;
        ar(2 + ch) += a_body * r;
        ar(5 + ch) += l * r;
      } else {
        const double w[U] = {u * k, u * t * k, a_body * k, l * k};
        for (int a = 0; a < U; ++a)
          for (int b = 0; b < P; ++b) aj_ch[ch](a, b) += w[a] * g(b);
        ar_ch[ch] += Eigen::Vector4d(u, u * t, a_body, l) * r;
      }
    }
    // By hand: Eigen's rank updates do not unroll at this size, and this loop is the pass.
    for (int a = 0; a < P; ++a) {
      const double kg = kk * g(a);
      for (int b = a; b < P; ++b) jj(a, b) += kg * g(b);
      jr(a) += kr * g(a);
    }
    if (colours.ok && known) {
      const double w[K] = {u * bk, u * t * bk, body_k[0], body_k[1], body_k[2], limb_k[0], limb_k[1], limb_k[2]};
      for (int a = 0; a < K; ++a)
        for (int b = 0; b < P; ++b) aj(a, b) += w[a] * g(b);
      ar(0) += u * br, ar(1) += u * t * br;
    }
  }
  for (int a = 0; a < P; ++a)
    for (int b = 0; b < a; ++b) jj(a, b) = jj(b, a);
  if (colours.ok && known) {
    const Eigen::Matrix<double, K, P> h = colours.known_inverse * aj;
    jj += -aj.transpose() * h - h.transpose() * aj + h.transpose() * colours.known_design * h;
    jr -= h.transpose() * ar;
  } else if (colours.ok) {
    for (int ch = 0; ch < 3; ++ch) {
      const Eigen::Matrix<double, U, P> h = colours.unknown_inverse[ch] * aj_ch[ch];
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

}  // namespace

RayCost::RayCost(const SmearedBody& body, RaySamples ray, double inv_noise, bool shaded, const double* start)
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

bool RayCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
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

void RayCost::Assess(const double* p, double* contrast, double* mean_square) const {
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

void RayCost::ResidualsAtStart(std::vector<double>* r) const {
  const size_t at = r->size();
  r->resize(at + 3 * ray_.dirs.size());
  Residuals(ray_.start_coverage, ShadeAtStart(), r->data() + at, nullptr);
}

DelayGramMatrix RayCost::DelayGram(const double* p) const {
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

template <typename Visit>
void RayCost::ForEachSample(const double* p, Visit visit) const {
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

void RayCost::CoverageAt(const double* p, std::vector<double>* c, std::vector<SmearGradient>* grad) const {
  if (!ray_.start_gradient.empty() && std::equal(p, p + kSmearParameters, start_.begin())) {
    *c = ray_.start_coverage, *grad = ray_.start_gradient;
    return;
  }
  c->resize(ray_.dirs.size()), grad->resize(ray_.dirs.size());
  ForEachSample(p, [&](size_t i, const SmearNodes& nodes) { (*c)[i] = nodes.Coverage(ray_.dirs[i], &(*grad)[i]); });
}

std::vector<double> RayCost::RowsSeen() const {
  if (ray_.rows.empty()) return std::vector<double>(ray_.dirs.size(), 0.0);
  const auto [lo, hi] = std::minmax_element(ray_.rows.begin(), ray_.rows.end());
  if (*hi - *lo <= kSharedRows) return std::vector<double>(ray_.dirs.size(), 0.5 * (*lo + *hi));
  return ray_.rows;
}

std::vector<cv::Vec3d> RayCost::ShadeAtStart() const {
  std::vector<cv::Vec3d> shade(ray_.start_basis.size());
  for (size_t i = 0; i < shade.size(); ++i) shade[i] = body_.shading->FromBasis(ray_.start_basis[i]);
  return shade;
}

void RayCost::Compute(const double* p, const std::vector<cv::Vec3d>& shade, double* residuals, RayColours* solved) const {
  std::vector<double> c(ray_.dirs.size());
  ForEachSample(p, [&](size_t i, const SmearNodes& nodes) { c[i] = nodes.Coverage(ray_.dirs[i], nullptr); });
  Residuals(c, shade, residuals, solved);
}

void RayCost::Residuals(const std::vector<double>& c, const std::vector<cv::Vec3d>& shade, double* residuals,
               RayColours* solved) const {
  const size_t n = ray_.dirs.size();
  RayColours colours = SolveColours(ray_, c, shade, 1.0 / inv_noise_);
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec3d I = ray_.image[i];
    const cv::Vec3d& B = colours.back[i];
    const cv::Vec3d F = colours.BodyAt(ray_, shade, i);
    for (int ch = 0; ch < 3; ++ch) residuals[3 * i + ch] = (I[ch] - B[ch] - c[i] * (F[ch] - B[ch])) * inv_noise_;
  }
  if (solved) *solved = std::move(colours);
}

double RayCost::Contrast(const RayColours& colours) {
  if (!colours.ok) return 0.0;
  cv::Vec3d mean_back(0, 0, 0);
  for (const cv::Vec3d& b : colours.back) mean_back += b;
  return cv::norm(colours.body - mean_back / static_cast<double>(colours.back.size()));
}

void RayCost::Reduce(const double* p, Reduced* out) const {
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

}  // namespace uphill::internal
