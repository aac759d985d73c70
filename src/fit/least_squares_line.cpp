#include "fit/least_squares_line.hpp"

#include <algorithm>
#include <cmath>

#include "fit/internal/line_problem.hpp"
#include "fit/model_comparison.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace fit_internal;

// r_i = (y_i − θ1 − θ0·x_i)·w_i in standardised coordinates; w_i = 1/σ_i, or 1 when inv_sigma
// is null (OLS). One block of N residuals: Ceres differentiates it with Jet<double, 2>, O(N).
struct LineResiduals {
  const double* x;
  const double* y;
  const double* inv_sigma;
  std::size_t n;

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    for (std::size_t i = 0; i < n; ++i) {
      const T r = y[i] - theta[1] - theta[0] * x[i];
      residuals[i] = inv_sigma ? r * inv_sigma[i] : r;
    }
    return true;
  }
};

FitReport FitLeastSquares(const LineData& data, const FitOptions& options, bool weighted) {
  const std::string method = weighted ? "WLS" : "OLS";
  ValidateLineData(data, weighted ? UncertaintyUse::kY : UncertaintyUse::kNone, method);
  const std::size_t n = data.size();

  const WeightedStandardised standardised = StandardiseWithUy(data, weighted);
  const Standardised& s = standardised.s;
  const std::vector<double>& inv_sigma = standardised.inv_sigma;

  Eigen::Vector2d theta =
      options.seed_with_closed_form ? ClosedFormLine(s, inv_sigma) : Eigen::Vector2d::Zero();
  ceres::Problem problem;  // owns the cost function
  auto* cost = new ceres::AutoDiffCostFunction<LineResiduals, ceres::DYNAMIC, 2>(
      new LineResiduals{s.x.data(), s.y.data(), weighted ? inv_sigma.data() : nullptr, n},
      static_cast<int>(n));
  problem.AddResidualBlock(cost, nullptr, theta.data());

  FitReport report =
      StartReport(weighted ? FitMethod::kWeightedLeastSquares : FitMethod::kOrdinaryLeastSquares, n,
                  weighted, weighted ? ErrorScaling::kUnscaled : ErrorScaling::kScaled,
                  options.outlier_threshold);
  report.solver = RunCeres(options, options.seed_with_closed_form, &problem);
  report.solver.refinement_steps = RefineGaussNewton({cost}, theta.data(), 2);

  const auto covariance_theta = CeresCovariance(&problem, theta.data(), 2);
  if (!covariance_theta)
    throw InputError("X",
                     "the values are too close together for a slope in binary64 "
                     "(rank-deficient design)");
  const LineParameters line = Unstandardise(s, theta, *covariance_theta);
  // Ceres' residuals are in units of sy for OLS; the unscaled OLS covariance means u(Y) = 1.
  report.covariance = weighted ? Eigen::MatrixXd(line.covariance)
                               : Eigen::MatrixXd(line.covariance / (s.sy * s.sy));

  long double chi2 = 0, total = 0, sum_log_sigma2 = 0;
  report.rows.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r_s = s.y[i] - theta(1) - theta(0) * s.x[i];
    const double r = s.sy * r_s;  // exact: sy is a power of two
    RowResult& row = report.rows[i];
    row.row = i;
    row.residual = r;
    row.fitted = data.y[i] - r;
    if (weighted) {
      row.sigma = data.u_y[i];
      row.normalised = r_s * inv_sigma[i];
      chi2 += static_cast<long double>(row.normalised) * row.normalised;
      const long double dev = s.y[i] * inv_sigma[i];
      total += dev * dev;
      sum_log_sigma2 += 2.0L * std::log(static_cast<long double>(data.u_y[i]));
    } else {
      chi2 += static_cast<long double>(r) * r;
      const long double dev = s.sy * static_cast<long double>(s.y[i]);
      total += dev * dev;
    }
  }
  report.chi2 = static_cast<double>(chi2);
  if (total > 0) report.r_squared = static_cast<double>(1.0L - chi2 / total);
  if (!weighted) {
    // Normalised residual r_i/s, s the residual standard deviation (none for an exact fit).
    const double sd = n > 2 ? std::sqrt(report.chi2 / static_cast<double>(n - 2)) : 0.0;
    for (RowResult& row : report.rows) {
      row.sigma = sd;
      row.normalised = sd > 0.0 ? row.residual / sd : 0.0;
    }
    if (!data.u_x.empty() || !data.u_y.empty())
      report.notes.push_back("OLS ignores the given uncertainties (use WLS or York)");
  } else if (!data.u_x.empty()) {
    report.notes.push_back("WLS ignores u(X) (York's fit uses it)");
  }
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), weighted);
  SetInformationCriteria(report, static_cast<double>(sum_log_sigma2));
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace

FitReport FitOrdinaryLeastSquares(const LineData& data, const FitOptions& options) {
  return FitLeastSquares(data, options, false);
}

FitReport FitWeightedLeastSquares(const LineData& data, const FitOptions& options) {
  return FitLeastSquares(data, options, true);
}

}  // namespace uphill
