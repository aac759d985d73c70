#include "fit/york_line.hpp"

#include <algorithm>
#include <cmath>

#include "fit/internal/line_problem.hpp"
#include "fit/model_comparison.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace fit_internal;

// r_i = (y_i − θ1 − θ0·x_i)/sqrt(uy_i² + θ0²·ux_i²), standardised: Σ r_i² is York's S.
struct YorkResiduals {
  const double* x;
  const double* y;
  const double* uy2;
  const double* ux2;
  std::size_t n;

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    using std::sqrt;
    const T k2 = theta[0] * theta[0];
    for (std::size_t i = 0; i < n; ++i)
      residuals[i] = (y[i] - theta[1] - theta[0] * x[i]) / sqrt(uy2[i] + k2 * ux2[i]);
    return true;
  }
};

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
    // WLS in u(Y), then effective-variance WLS (weights 1/(uy² + k²ux²) at the previous slope):
    // each step is a closed form, and two of them put the seed within a fraction of a standard
    // error of York's line, where Ceres converges in a few steps.
    std::vector<double> inv_sigma(n);
    for (std::size_t i = 0; i < n; ++i) inv_sigma[i] = 1.0 / s.uy[i];
    theta = ClosedFormLine(s, inv_sigma);
    for (int pass = 0; pass < 2; ++pass) {
      const double k2 = theta(0) * theta(0);
      for (std::size_t i = 0; i < n; ++i) inv_sigma[i] = 1.0 / std::sqrt(uy2[i] + k2 * ux2[i]);
      theta = ClosedFormLine(s, inv_sigma);
    }
  }
  ceres::Problem problem;  // owns the cost function
  auto* cost = new ceres::AutoDiffCostFunction<YorkResiduals, ceres::DYNAMIC, 2>(
      new YorkResiduals{s.x.data(), s.y.data(), uy2.data(), ux2.data(), n}, static_cast<int>(n));
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
    sum_log_sigma2 += 2.0L * std::log(static_cast<long double>(row.sigma));
  }
  report.chi2 = static_cast<double>(chi2);
  if (std::all_of(data.u_x.begin(), data.u_x.end(), [](double u) { return u == 0.0; }))
    report.notes.push_back("all u(X) are 0: York's line is the WLS line");
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), true);
  SetInformationCriteria(report, static_cast<double>(sum_log_sigma2));
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace uphill
