#include "fit/york_line.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "fit/internal/line_problem.hpp"
#include "fit/model_comparison.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace fit_internal;

// r_i = (y_i − θ1 − θ0·x_i)·w_i, w_i = 1/sqrt(uy_i² + θ0²·ux_i²), standardised: Σ r_i² is York's
// S. Analytic Jacobian, ∂r_i/∂θ0 = −w_i·ξ_i with ξ_i = x_i + θ0·ux_i²·w_i·r_i (the adjusted x of
// the header), ∂r_i/∂θ1 = −w_i: one branch-free pass over the rows that the compiler vectorises
// (york_line.cpp is built with -fno-math-errno so that sqrt needs no errno path). Why not
// AutoDiffCostFunction: Jet<double, 2> arithmetic costs ~4× more per row, and at 10^6 rows the
// cost function is evaluated ~6 times per fit.
class YorkCost final : public ceres::CostFunction {
 public:
  YorkCost(const double* x, const double* y, const double* uy2, const double* ux2, std::size_t n)
      : x_(x), y_(y), uy2_(uy2), ux2_(ux2), n_(n) {
    set_num_residuals(static_cast<int>(n));
    mutable_parameter_block_sizes()->push_back(2);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double k = parameters[0][0], c = parameters[0][1], k2 = k * k;
    double* jacobian = jacobians ? jacobians[0] : nullptr;
    if (jacobian) {
      for (std::size_t i = 0; i < n_; ++i) {
        const double w = 1.0 / std::sqrt(uy2_[i] + k2 * ux2_[i]);
        const double r = (y_[i] - c - k * x_[i]) * w;
        residuals[i] = r;
        jacobian[2 * i] = -w * (x_[i] + k * ux2_[i] * w * r);
        jacobian[2 * i + 1] = -w;
      }
    } else {
      for (std::size_t i = 0; i < n_; ++i)
        residuals[i] = (y_[i] - c - k * x_[i]) / std::sqrt(uy2_[i] + k2 * ux2_[i]);
    }
    return true;
  }

 private:
  const double *x_, *y_, *uy2_, *ux2_;
  std::size_t n_;
};

// The closed-form seed: York's effective-variance iteration, each pass the weighted
// least-squares line with weights W_i = 1/(uy² + k²ux²) at the previous slope, by sums over the
// standardised rows (centred and scaled, so the 2×2 normal equations are well conditioned and
// double sums lose nothing a seed needs). Starts at WLS in u(Y) (k = 0); stops when the slope
// moves by < 1e-9 relative (York's iteration converges linearly, typically 5-10 passes), so that
// Ceres starts within rounding-noise of its minimum and needs one or two steps, and the
// Gauss-Newton refinement finishes at ε. Eigen arrays: the passes vectorise.
Eigen::Vector2d YorkSeed(const Eigen::Map<const Eigen::ArrayXd>& x,
                         const Eigen::Map<const Eigen::ArrayXd>& y,
                         const Eigen::Map<const Eigen::ArrayXd>& uy2,
                         const Eigen::Map<const Eigen::ArrayXd>& ux2) {
  Eigen::ArrayXd w(x.size());
  double k = 0.0, c = 0.0;
  for (int pass = 0; pass < 50; ++pass) {
    w = (uy2 + (k * k) * ux2).inverse();
    const double sw = w.sum();
    const double xm = (w * x).sum() / sw, ym = (w * y).sum() / sw;
    const double sxx = (w * (x - xm).square()).sum();
    const double sxy = (w * (x - xm) * (y - ym)).sum();
    const double next = sxy / sxx;
    const bool done = std::abs(next - k) <= 1e-9 * std::abs(next);
    k = next;
    c = ym - k * xm;
    if (done || !std::isfinite(k)) break;
  }
  return {k, c};
}

}  // namespace

FitReport FitErrorsInVariables(const LineData& data, const FitOptions& options) {
  ValidateLineData(data, UncertaintyUse::kXY, "York's fit");
  const std::size_t n = data.size();

  std::vector<double> centre_weights(n);
  const double u_min = *std::min_element(data.u_y.begin(), data.u_y.end());
  for (std::size_t i = 0; i < n; ++i) {
    const double ratio = u_min / data.u_y[i];
    centre_weights[i] = ratio * ratio;
  }
  const Standardised s = Standardise(data, centre_weights, true, true);
  RequireRepresentable(s.uy, "u(Y)");
  std::vector<double> uy2(n), ux2(n);
  for (std::size_t i = 0; i < n; ++i) {
    uy2[i] = s.uy[i] * s.uy[i];
    ux2[i] = s.ux[i] * s.ux[i];
  }

  Eigen::Vector2d theta = Eigen::Vector2d::Zero();
  if (options.seed_with_closed_form) {
    using Map = Eigen::Map<const Eigen::ArrayXd>;
    const Eigen::Index size = static_cast<Eigen::Index>(n);
    theta = YorkSeed(Map(s.x.data(), size), Map(s.y.data(), size), Map(uy2.data(), size),
                     Map(ux2.data(), size));
    if (!theta.allFinite()) theta.setZero();  // degenerate data: let Ceres start cold
  }
  ceres::Problem problem;  // owns the cost function
  auto* cost = new YorkCost(s.x.data(), s.y.data(), uy2.data(), ux2.data(), n);
  problem.AddResidualBlock(cost, nullptr, theta.data());

  FitReport report;
  report.method = FitMethod::kErrorsInVariables;
  report.n = n;
  report.uses_stated_uncertainties = true;
  report.primary_scaling = ErrorScaling::kUnscaled;
  report.outlier_threshold = options.outlier_threshold;
  report.solver = RunCeres(options, options.seed_with_closed_form, &problem);
  report.solver.refinement_steps = RefineGaussNewton({cost}, theta.data(), 2);

  // At the solution JᵀJ is York's information Σ W_i (ξ_i, 1)ᵀ(ξ_i, 1) (see the header).
  const auto covariance_theta = CeresCovariance(&problem, theta.data(), 2);
  if (!covariance_theta)
    throw InputError("X",
                     "the values are too close together for a slope in binary64 "
                     "(rank-deficient design)");
  const LineParameters line = Unstandardise(s, theta, *covariance_theta);
  report.covariance = line.covariance;

  long double chi2 = 0, sum_log_sigma2 = 0;
  const double k2 = theta(0) * theta(0);
  report.rows.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double e_s = s.y[i] - theta(1) - theta(0) * s.x[i];
    const double sigma_s = std::sqrt(uy2[i] + k2 * ux2[i]);
    RowResult& row = report.rows[i];
    row.row = i;
    row.residual = s.sy * e_s;
    row.fitted = data.y[i] - row.residual;
    row.sigma = s.sy * sigma_s;
    row.normalised = e_s / sigma_s;
    chi2 += static_cast<long double>(row.normalised) * row.normalised;
    // ln σ_i² = ln σ_s² + 2 ln sy: the double log (the long-double one costs 5× more, and AIC
    // needs no 19 digits); the constant term once, below.
    sum_log_sigma2 += std::log(sigma_s * sigma_s);
  }
  sum_log_sigma2 += 2.0L * static_cast<long double>(n) * std::log(static_cast<long double>(s.sy));
  report.chi2 = static_cast<double>(chi2);
  if (std::all_of(data.u_x.begin(), data.u_x.end(), [](double u) { return u == 0.0; }))
    report.notes.push_back("all u(X) are 0: York's line is the WLS line");
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), true);
  SetInformationCriteria(report, static_cast<double>(sum_log_sigma2));
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace uphill
