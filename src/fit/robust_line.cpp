#include "fit/robust_line.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "fit/internal/line_problem.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace fit_internal;

// One row: r = (y − θ1 − θ0·x)/σ in standardised coordinates. Ceres applies a loss per residual
// block, so every row is its own block.
struct RowResidual {
  double x, y, inv_sigma;

  template <typename T>
  bool operator()(const T* theta, T* residual) const {
    residual[0] = (y - theta[1] - theta[0] * x) * inv_sigma;
    return true;
  }
};
using RowCost = ceres::AutoDiffCostFunction<RowResidual, 1, 2>;

constexpr double kHuberDefault = 1.345;            // 95 % efficiency at the normal distribution
constexpr double kCauchyDefault = 2.3849;          // likewise
constexpr double kMadToSigma = 1.482602218505602;  // 1/Φ⁻¹(3/4)

double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return lower + (upper - lower) / 2.0;
}

}  // namespace

FitReport FitRobust(const LineData& data, const RobustOptions& options) {
  ValidateLineData(data, UncertaintyUse::kOptionalY, "the robust fit");
  const std::size_t n = data.size();
  const bool stated = !data.u_y.empty();
  if (options.loss_scale != 0.0 && !(options.loss_scale > 0.0 && std::isfinite(options.loss_scale)))
    throw InputError("loss scale", "must be finite and > 0, or 0 for the default (got " +
                                       Num(options.loss_scale) + ")");
  const double delta = options.loss_scale > 0.0
                           ? options.loss_scale
                           : (options.loss == RobustLoss::kHuber ? kHuberDefault : kCauchyDefault);
  const FitOptions& fit = options.fit;

  WeightedStandardised standardised = StandardiseWithUy(data, stated);
  const Standardised& s = standardised.s;
  std::vector<double>& inv_sigma = standardised.inv_sigma;
  // The least-squares line: the seed, and (without u(Y)) the residuals for the first scale.
  const Eigen::Vector2d least_squares = ClosedFormLine(s, inv_sigma);
  FitReport report = StartReport(FitMethod::kRobust, n, stated, ErrorScaling::kUnscaled,
                                 fit.outlier_threshold);
  if (!stated) inv_sigma.assign(n, 1.0);

  // Without u(Y) the common σ enters through the loss alone: ρ_{δσ}(r²) = σ²·ρ_δ((r/σ)²) for
  // both losses, so a new σ is a new loss object, not new cost functions.
  const double huber_delta = options.loss == RobustLoss::kHuber ? delta : kHuberDefault;
  double sigma = 1.0;  // standardised units; stays 1 when u(Y) is given
  bool scale_from_ssr = false;
  const auto robust_scale = [&](const Eigen::Vector2d& line) {
    std::vector<double> abs_residual(n);
    long double ssr = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double r = s.y[i] - line(1) - line(0) * s.x[i];
      abs_residual[i] = std::abs(r);
      ssr += static_cast<long double>(r) * r;
    }
    // Residuals about a fitted line have median ≈ 0: the MAD is the median |r|.
    double scale = kMadToSigma * Median(abs_residual);
    if (!(scale > 0.0)) {
      scale_from_ssr = true;
      scale = n > 2 ? std::sqrt(static_cast<double>(ssr) / static_cast<double>(n - 2)) : 0.0;
    }
    return scale > 0.0 ? scale : 1.0;
  };
  if (!stated) sigma = robust_scale(least_squares);

  Eigen::Vector2d theta = fit.seed_with_closed_form ? least_squares : Eigen::Vector2d::Zero();
  // Cost functions live in one vector and the loss is shared; Ceres owns neither, which spares
  // it a reference-count map entry per row.
  std::vector<RowCost> costs;
  costs.reserve(n);
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunctionWrapper loss(new ceres::HuberLoss(huber_delta * sigma), ceres::TAKE_OWNERSHIP);
  std::vector<const ceres::CostFunction*> cost_pointers(n);
  for (std::size_t i = 0; i < n; ++i) {
    costs.emplace_back(new RowResidual{s.x[i], s.y[i], inv_sigma[i]});
    cost_pointers[i] = &costs.back();
    problem.AddResidualBlock(&costs.back(), &loss, theta.data());
  }
  const auto solve = [&] {
    const SolverInfo info = RunCeres(fit, fit.seed_with_closed_form, &problem);
    report.solver.converged = info.converged;
    report.solver.iterations += info.iterations;
    report.solver.seconds += info.seconds;
    report.solver.termination = info.termination;
    report.solver.seeded_with_closed_form = info.seeded_with_closed_form;
  };
  // Seeded: Newton steps on the Huber objective from the least-squares line (cheap, O(N) each,
  // exact in a few steps for Huber's piecewise-quadratic loss) bring the start next to the
  // solution, and Ceres' linearly converging steps are few. Cold: Ceres from 0.
  if (fit.seed_with_closed_form)
    RefineGaussNewton(cost_pointers, theta.data(), 2, std::nullopt, &loss);
  else
    solve();
  if (!stated) {
    // The least-squares residuals overstate σ when there are gross errors (the line is dragged
    // toward them): re-estimate σ from the robust residuals until it is a fixed point (to
    // 1e-12, so that the result does not depend on the path). The intermediate lines only feed
    // σ, so Newton refinement replaces full Ceres solves.
    bool settled = false;
    for (int round = 0; round < 50 && !settled; ++round) {
      const double next = robust_scale(theta);
      settled = std::abs(next - sigma) <= 1e-12 * sigma;
      sigma = next;
      loss.Reset(new ceres::HuberLoss(huber_delta * sigma), ceres::TAKE_OWNERSHIP);
      if (!settled) RefineGaussNewton(cost_pointers, theta.data(), 2, std::nullopt, &loss);
    }
    if (!settled)
      report.notes.push_back("the robust scale did not settle in 50 rounds (last sigma used)");
    if (scale_from_ssr)
      report.notes.push_back(
          "more than half the rows lie on the line (MAD = 0): the robust scale "
          "is the residual SD");
    report.notes.push_back("robust scale sigma = 1.4826 MAD of the robust residuals = " +
                           Num(sigma * s.sy));
  }
  // Cauchy's loss is not convex: it starts from Huber's solution, with Huber's scale.
  if (options.loss == RobustLoss::kCauchy) {
    loss.Reset(new ceres::CauchyLoss(delta * sigma), ceres::TAKE_OWNERSHIP);
    if (fit.seed_with_closed_form)
      RefineGaussNewton(cost_pointers, theta.data(), 2, std::nullopt, &loss);
  }
  solve();  // Ceres on the final loss and scale
  report.solver.refinement_steps =
      RefineGaussNewton(cost_pointers, theta.data(), 2, std::nullopt, &loss);

  // With the loss applied, Ceres' covariance is the weighted LS one at the final weights.
  const auto covariance_theta = CeresCovariance(&problem, theta.data(), 2, true);
  if (!covariance_theta)
    throw InputError("X",
                     "too few rows keep a non-zero weight to determine the line "
                     "(rank-deficient weighted design)");
  // Ceres' residuals are r/σ with σ in the loss (see above): × σ² for the σ-normalised one.
  const LineParameters line = Unstandardise(s, theta, *covariance_theta * (sigma * sigma));
  report.covariance = line.covariance;

  long double chi2 = 0;
  report.rows.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double e_s = s.y[i] - theta(1) - theta(0) * s.x[i];
    const double residual = e_s * inv_sigma[i];  // as Ceres sees it
    const double z = residual / sigma;           // normalised
    double rho[3];
    loss.Evaluate(residual * residual, rho);
    RowResult& row = report.rows[i];
    row.row = i;
    row.residual = s.sy * e_s;
    row.fitted = data.y[i] - row.residual;
    row.sigma = stated ? data.u_y[i] : sigma * s.sy;
    row.normalised = z;
    row.weight = rho[1];
    chi2 += static_cast<long double>(rho[1]) * z * z;
    if (std::abs(z) > delta) report.downweighted.push_back({i, rho[1], z});
  }
  report.chi2 = static_cast<double>(chi2);
  report.notes.push_back(std::string(options.loss == RobustLoss::kHuber ? "Huber" : "Cauchy") +
                         " loss, scale " + Num(delta) + " sigma; " +
                         std::to_string(report.downweighted.size()) + " of " + std::to_string(n) +
                         " rows down-weighted (|r/sigma| > scale)");
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), false);
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace uphill
