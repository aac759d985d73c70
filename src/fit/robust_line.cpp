#include "fit/robust_line.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "internal/compressed_cost.hpp"
#include "internal/least_squares_moments.hpp"
#include "internal/line_problem.hpp"
#include "internal/row_model.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

using namespace internal;

constexpr double kHuberDefault = 1.345;            // 95 % efficiency at the normal distribution
constexpr double kCauchyDefault = 2.3849;          // likewise
constexpr double kMadToSigma = 1.482602218505602;  // 1/Φ⁻¹(3/4)
constexpr std::size_t kRows = 1024;                // per chunk of the row loops

// The robust criterion Σ ρ(z_i²) in standardised coordinates, z_i = e_i/σ_i,
// e_i = y_i − c − k·x_i, σ_i = u(Y_i)/sy (stated) or one σ (estimated), with Huber's loss
// ρ(s) = s for |z| ≤ δ, 2δ|z| − δ² beyond, or Cauchy's ρ(s) = δ²·ln(1 + s/δ²).
// Ceres sees it compressed to 3 residuals (compressed_cost.hpp) with the sums of Ceres' own
// robustified Gauss-Newton (IRLS) model: cost Σρ, gradient Σ ρ'·z·∂z/∂θ, matrix
// Σ ρ'·(∂z/∂θ)(∂z/∂θ)ᵀ - valid since Σρ ≥ Σρ'·z² ≥ gᵀ(JᵀWJ)⁻¹g for both losses (ρ(s) ≥ ρ'(s)·s).
// Its ceres::Covariance is the weighted least-squares covariance at the final weights,
// (Σ w_i (x_i, 1)ᵀ(x_i, 1)/σ_i²)⁻¹, the usual IRLS approximation. The exact Hessian for the Newton
// polish weights each row by ρ' + 2ρ''·s: 1 for Huber's inliers, 0 for its outliers (the loss is
// linear in |z| there).
class RobustCost final : public CompressedLineCost {
 public:
  // sigma_s: the common σ in standardised units, or 0 for σ_i = u(Y_i)/sy (the view's u(Y)).
  RobustCost(const StandardisedView& v, RobustLoss loss, double delta, double sigma_s)
      : v_(v), loss_(loss), delta_(delta), sigma_s_(sigma_s) {}

 private:
  bool RowSums(const double* theta, bool with_hessian, LineSums* sums) const override {
    long double acc[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    const bool stated = v_.uy != nullptr;
    for (std::size_t i = 0; i < v_.n; i += kRows) {
      const std::size_t m = std::min(kRows, v_.n - i);
      if (loss_ == RobustLoss::kHuber)
        stated ? Chunk<RobustLoss::kHuber, true>(i, m, theta[0], theta[1], acc)
               : Chunk<RobustLoss::kHuber, false>(i, m, theta[0], theta[1], acc);
      else
        stated ? Chunk<RobustLoss::kCauchy, true>(i, m, theta[0], theta[1], acc)
               : Chunk<RobustLoss::kCauchy, false>(i, m, theta[0], theta[1], acc);
    }
    sums->rr = static_cast<double>(acc[0]);
    sums->jtr << -static_cast<double>(acc[1]), -static_cast<double>(acc[2]);
    sums->jtj << static_cast<double>(acc[3]), static_cast<double>(acc[4]), static_cast<double>(acc[4]),
        static_cast<double>(acc[5]);
    sums->hessian = sums->jtj;
    if (with_hessian)
      sums->hessian << static_cast<double>(acc[6]), static_cast<double>(acc[7]), static_cast<double>(acc[7]),
          static_cast<double>(acc[8]);
    return true;
  }

  // Σρ; Σ ρ'·z·(x, 1)/σ; Σ ρ'·(x², x, 1)/σ²; Σ (ρ' + 2ρ''s)·(x², x, 1)/σ² over one chunk.
  template <RobustLoss kLoss, bool kStated>
  [[gnu::noinline, gnu::target_clones("avx2", "default")]] void Chunk(std::size_t i, std::size_t m, double k,
                                                                      double c, long double acc[9]) const {
    const double *x = v_.x + i, *y = v_.y + i, *u = kStated ? v_.uy + i : nullptr;
    const double x0 = v_.x0, y0 = v_.y0, isx = v_.inv_sx, isy = v_.inv_sy, delta = delta_, sigma = sigma_s_;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0, s8 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5, s6, s7, s8)
    for (std::size_t j = 0; j < m; ++j) {
      const double xs = (x[j] - x0) * isx;
      const double e = (y[j] - y0) * isy - c - k * xs;
      double inv = 1.0 / sigma;
      if constexpr (kStated) inv = 1.0 / (u[j] * isy);
      const double z = e * inv;
      // ρ(z²), ρ'(z²) and ρ' + 2ρ''·z², written in the loop (a helper taking references makes
      // GCC keep them in memory and not vectorise). Huber's as selects between both arms (the file
      // is built with -fno-trapping-math, so the compiler computes both instead of branching);
      // δ/max(|z|, δ) is exactly 1 for inliers.
      double rho, weight, newton_weight;
      if constexpr (kLoss == RobustLoss::kHuber) {
        const double a = std::abs(z);
        const bool inlier = a <= delta;
        const double quadratic = z * z, linear = 2.0 * delta * a - delta * delta;
        rho = inlier ? quadratic : linear;
        weight = delta / (inlier ? delta : a);
        newton_weight = inlier ? 1.0 : 0.0;
      } else {
        const double d2 = delta * delta, t = z * z / d2;
        weight = 1.0 / (1.0 + t);
        rho = d2 * std::log1p(t);
        newton_weight = weight - 2.0 * t * weight * weight;
      }
      const double g = weight * z * inv, w = weight * inv * inv, h = newton_weight * inv * inv;
      s0 += rho, s1 += g * xs, s2 += g, s3 += w * xs * xs, s4 += w * xs, s5 += w;
      s6 += h * xs * xs, s7 += h * xs, s8 += h;
    }
    acc[0] += s0, acc[1] += s1, acc[2] += s2, acc[3] += s3, acc[4] += s4, acc[5] += s5;
    acc[6] += s6, acc[7] += s7, acc[8] += s8;
  }

  StandardisedView v_;
  RobustLoss loss_;
  double delta_, sigma_s_;
};

// 1.4826·median |e_i| of the standardised residuals at θ; 0 if more than half of them are 0.
// `buffer` (N values) is reused between calls.
double MadScale(const StandardisedView& v, const Eigen::Vector2d& theta, std::vector<double>* buffer) {
  buffer->resize(v.n);
  double* r = buffer->data();
  const double k = theta(0), c = theta(1);
  for (std::size_t i = 0; i < v.n; ++i) r[i] = std::abs((v.y[i] - v.y0) * v.inv_sy - c - k * (v.x[i] - v.x0) * v.inv_sx);
  const std::size_t mid = v.n / 2;
  std::nth_element(r, r + mid, r + v.n);
  double median = r[mid];
  if (v.n % 2 == 0) median = (median + *std::max_element(r, r + mid)) / 2.0;  // lower middle
  return kMadToSigma * median;
}

}  // namespace

FitReport FitRobust(const LineData& data, const RobustOptions& options) {
  const StandardisedView view = ValidateAndView(data, UncertaintyUse::kOptionalY, "the robust fit");
  const std::size_t n = data.size();
  const bool stated = !data.u_y.empty();
  if (options.loss_scale != 0.0 && !(options.loss_scale > 0.0 && std::isfinite(options.loss_scale)))
    throw InputError("loss scale", "must be finite and > 0, or 0 for the default (got " + ExactText(options.loss_scale) + ")");
  const double delta = options.loss_scale > 0.0 ? options.loss_scale
                                                 : (options.loss == RobustLoss::kHuber ? kHuberDefault : kCauchyDefault);
  const FitOptions& fit = options.fit;
  ValidateFitOptions(fit);
  FitReport report = StartReport(FitMethod::kRobust, n, stated, ErrorScaling::kUnscaled, fit.outlier_threshold);

  // The least-squares line (closed form from the moments): the start, and without u(Y) the
  // residuals of the first scale estimate.
  Eigen::Vector2d least_squares = Eigen::Vector2d::Zero();
  {
    const LeastSquaresCost ls(TakeMoments(view, stated));
    const LineSums* at_zero = ls.Sums(least_squares.data());
    if (at_zero) least_squares = at_zero->jtj.ldlt().solve(-at_zero->jtr);
    if (!least_squares.allFinite()) least_squares.setZero();
  }
  std::vector<double> buffer;
  double sigma = 1.0;  // the common σ in standardised units (estimated); unused when stated
  bool scale_from_ssr = false;
  const auto estimate_scale = [&](const Eigen::Vector2d& line) {
    double scale = MadScale(view, line, &buffer);
    if (!(scale > 0.0)) {
      // More than half the rows on the line: the residual SD instead.
      scale_from_ssr = true;
      long double ssr = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const double e = (view.y[i] - view.y0) * view.inv_sy - line(1) - line(0) * (view.x[i] - view.x0) * view.inv_sx;
        ssr += static_cast<long double>(e) * e;
      }
      scale = n > 2 ? std::sqrt(static_cast<double>(ssr) / static_cast<double>(n - 2)) : 0.0;
    }
    return scale > 0.0 ? scale : 1.0;
  };
  if (!stated) sigma = estimate_scale(least_squares);

  Eigen::Vector2d theta = fit.seed_with_closed_form ? least_squares : Eigen::Vector2d::Zero();
  // Ceres on the current loss and scale, from θ, then Newton's polish (exact Hessian): one
  // problem per stage, since a new σ or loss is a new cost function.
  std::unique_ptr<ceres::Problem> problem;
  RobustCost* cost = nullptr;
  const auto solve = [&](RobustLoss loss, double loss_delta) {
    problem = std::make_unique<ceres::Problem>();
    cost = new RobustCost(view, loss, loss_delta, stated ? 0.0 : sigma);
    problem->AddResidualBlock(cost, nullptr, theta.data());
    const SolverInfo info = RunCeres(fit, fit.seed_with_closed_form, problem.get());
    report.solver.converged = info.converged;
    report.solver.iterations += info.iterations;
    report.solver.seconds += info.seconds;
    report.solver.termination = info.termination;
    report.solver.seeded_with_closed_form = info.seeded_with_closed_form;
    report.solver.refinement_steps = RefineNewton(*cost, theta.data());
  };
  const double huber_delta = options.loss == RobustLoss::kHuber ? delta : kHuberDefault;
  solve(RobustLoss::kHuber, huber_delta);
  if (!stated) {
    // The least-squares residuals overstate σ when there are gross errors (the line is dragged
    // toward them): re-estimate σ from the robust residuals until it is a fixed point (to 1e-12,
    // so that the result does not depend on the path).
    bool settled = false;
    for (int round = 0; round < 50 && !settled; ++round) {
      const double next = estimate_scale(theta);
      settled = std::abs(next - sigma) <= 1e-12 * sigma;
      sigma = next;
      if (!settled) solve(RobustLoss::kHuber, huber_delta);
    }
    if (!settled) report.notes.push_back("the robust scale did not settle in 50 rounds (last sigma used)");
    if (scale_from_ssr)
      report.notes.push_back("more than half the rows lie on the line (MAD = 0): the robust scale is the residual SD");
    report.notes.push_back("robust scale sigma = 1.4826 MAD of the robust residuals = " + ExactText(sigma * view.sy));
  }
  // Cauchy's loss is not convex: it starts from Huber's solution, with Huber's scale.
  if (options.loss == RobustLoss::kCauchy || !stated) solve(options.loss, delta);

  const auto covariance_theta = CeresCovariance(problem.get(), theta.data(), 2);
  if (!covariance_theta)
    throw InputError("X", "too few rows keep a non-zero weight to determine the line (rank-deficient weighted design)");
  const Standardisation s{view.x0, view.y0, view.sx, view.sy};
  const LineParameters line = Unstandardise(s, theta, *covariance_theta);
  report.covariance = line.covariance;

  LineRowModel& model = report.row_model;
  model.valid = true;
  model.x0 = view.x0, model.y0 = view.y0, model.inv_sx = view.inv_sx, model.inv_sy = view.inv_sy;
  model.sy = view.sy, model.k = theta(0), model.c = theta(1);
  model.sigma = stated ? LineRowModel::Sigma::kUy : LineRowModel::Sigma::kCommon;
  model.sigma_common = stated ? 0.0 : sigma * view.sy;
  model.weight = options.loss == RobustLoss::kHuber ? LineRowModel::Weight::kHuber : LineRowModel::Weight::kCauchy;
  model.loss_scale = delta;

  long double chi2 = 0;
  if (fit.keep_rows) report.rows.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const RowResult row = internal::EvaluateRow(model, fit.outlier_threshold, i, data.x[i], data.y[i], 0.0,
                                                    stated ? data.u_y[i] : 0.0);
    chi2 += static_cast<long double>(row.weight) * row.normalised * row.normalised;
    if (std::abs(row.normalised) > delta) report.downweighted.push_back({i, row.weight, row.normalised});
    if (row.outlier) report.outliers.push_back(i);
    if (fit.keep_rows) report.rows.push_back(row);
  }
  report.chi2 = static_cast<double>(chi2);
  report.notes.push_back(std::string(options.loss == RobustLoss::kHuber ? "Huber" : "Cauchy") + " loss, scale " +
                         ExactText(delta) + " sigma; " + std::to_string(report.downweighted.size()) + " of " +
                         std::to_string(n) + " rows down-weighted (|r/sigma| > scale)");
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), false, true);
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace uphill
