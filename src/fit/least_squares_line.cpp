#include "fit/least_squares_line.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "internal/compressed_cost.hpp"
#include "internal/least_squares_moments.hpp"
#include "internal/line_problem.hpp"
#include "internal/log_sum.hpp"
#include "internal/row_model.hpp"
#include "fit/model_comparison.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace internal;

constexpr std::size_t kRows = 1024;  // per chunk of the rows' pass

// One chunk of the rows' pass: the standardised residuals e_j and normalised residuals z_j of the
// row model (row_model.hpp's formulas, so the stored and on-demand rows agree), Σ z² (WLS) or
// Σ e² (OLS), and per block of kBlock rows the largest |z| (WLS) or |e| (OLS), so that the scan
// for outliers looks only into blocks that hold one.
constexpr std::size_t kBlock = 64;
template <bool kWeighted>
[[gnu::noinline, gnu::target_clones("avx2", "default")]] double ChunkResiduals(const double* x, const double* y,
                                                                             const double* u, std::size_t m,
                                                                             const LineRowModel& model, double* e,
                                                                             double* z, double* block_max) {
  const double x0 = model.x0, y0 = model.y0, isx = model.inv_sx, isy = model.inv_sy, k = model.k, c = model.c;
  double sum = 0;
  for (std::size_t b = 0; b < m; b += kBlock) {
    const std::size_t end = std::min(m, b + kBlock);
    double largest = 0;
#pragma omp simd reduction(+ : sum) reduction(max : largest)
    for (std::size_t j = b; j < end; ++j) {
      const double xs = (x[j] - x0) * isx;
      const double ej = (y[j] - y0) * isy - c - k * xs;
      e[j] = ej;
      if constexpr (kWeighted) {
        const double zj = ej / (u[j] * isy);
        z[j] = zj;
        sum += zj * zj;
        largest = std::max(largest, std::abs(zj));
      } else {
        sum += ej * ej;
        largest = std::max(largest, std::abs(ej));
      }
    }
    block_max[b / kBlock] = largest;
  }
  return sum;
}

FitReport FitLeastSquares(const LineData& data, const FitOptions& options, bool weighted) {
  const std::string method = weighted ? "WLS" : "OLS";
  const StandardisedView view =
      ValidateAndView(data, weighted ? UncertaintyUse::kY : UncertaintyUse::kNone, method);
  ValidateFitOptions(options);
  const std::size_t n = data.size();
  const LineMoments moments = TakeMoments(view, weighted);

  ceres::Problem problem;  // owns the cost function
  auto* cost = new LeastSquaresCost(moments);
  Eigen::Vector2d theta = Eigen::Vector2d::Zero();
  problem.AddResidualBlock(cost, nullptr, theta.data());
  FitReport report =
      StartReport(weighted ? FitMethod::kWeightedLeastSquares : FitMethod::kOrdinaryLeastSquares, n, weighted,
                  weighted ? ErrorScaling::kUnscaled : ErrorScaling::kScaled, options.outlier_threshold);
  if (options.seed_with_closed_form) {
    // The closed form: one Gauss-Newton step from 0 solves a linear least-squares problem
    // exactly, so Ceres has nothing to iterate; the Newton polish below confirms it.
    const LineSums* at_zero = cost->Sums(theta.data());
    if (at_zero) theta = at_zero->jtj.ldlt().solve(-at_zero->jtr);
    if (!theta.allFinite())
      throw InputError("X", "the values are too close together for a slope in binary64 (rank-deficient design)");
    report.solver.converged = true;
    report.solver.seeded_with_closed_form = true;
    report.solver.termination =
        "CONVERGENCE: closed form (a linear least-squares problem: one Gauss-Newton step is exact)";
  } else {
    report.solver = RunCeres(options, false, &problem);
  }
  // Newton's step on a quadratic is exact: taken without a cost check (the moment-based cost
  // cancels for closely fitting data and could not judge a step at the rounding level anyway).
  report.solver.refinement_steps = RefineNewton(*cost, theta.data(), std::numeric_limits<double>::infinity());

  const auto covariance_theta = CeresCovariance(&problem, theta.data(), 2);
  if (!covariance_theta)
    throw InputError("X", "the values are too close together for a slope in binary64 (rank-deficient design)");
  const Standardisation s{view.x0, view.y0, view.sx, view.sy};
  const LineParameters line = Unstandardise(s, theta, *covariance_theta);
  // Ceres' residuals are in units of sy for OLS; the unscaled OLS covariance means u(Y) = 1.
  report.covariance = weighted ? Eigen::MatrixXd(line.covariance) : Eigen::MatrixXd(line.covariance / (s.sy * s.sy));

  LineRowModel& model = report.row_model;
  model.valid = true;
  model.x0 = view.x0, model.y0 = view.y0, model.inv_sx = view.inv_sx, model.inv_sy = view.inv_sy;
  model.sy = view.sy, model.k = theta(0), model.c = theta(1);
  model.sigma = weighted ? LineRowModel::Sigma::kUy : LineRowModel::Sigma::kCommon;

  // The rows' pass: χ² (OLS: the residual sum of squares), Σ ln u(Y)², the outliers. For OLS the
  // normalised residual e/s needs s = sqrt(SSR/(N − 2)) from this very pass: rows beyond the
  // threshold by an estimate of s (from the moments, with a wide margin) are kept as candidates
  // and decided once s is known (the estimate is good to ~1e-8 where it is used, so a margin of
  // 1e-3 is ample); if the estimate is useless (a nearly exact fit), a second pass.
  const double threshold = options.outlier_threshold;
  const double ssr_estimate = std::max(cost->Sums(theta.data())->rr, 0.0);
  const double e_candidate =
      n > 2 ? 0.999 * threshold * std::sqrt(ssr_estimate / static_cast<double>(n - 2)) : 0.0;
  const std::size_t candidate_limit = n / 64 + 1024;
  std::vector<std::size_t> candidates;
  // A moment-based SSR that has lost more than half its digits to cancellation is no estimate.
  bool candidates_complete = e_candidate > 0.0 && ssr_estimate > 1e-8 * moments.yy;
  long double chi2 = 0;
  LogSum log_u;
  double e[kRows], z[kRows], block_max[kRows / kBlock];
  // Appends the rows of the chunk at i whose |v| exceeds `bound` (blocks below it skipped).
  const auto scan = [&](std::size_t i, std::size_t m, const double* v, double bound, std::vector<std::size_t>* out) {
    for (std::size_t b = 0; b < m; b += kBlock) {
      if (!(block_max[b / kBlock] > bound)) continue;
      for (std::size_t j = b; j < std::min(m, b + kBlock); ++j)
        if (std::abs(v[j]) > bound) out->push_back(i + j);
    }
  };
  for (std::size_t i = 0; i < n; i += kRows) {
    const std::size_t m = std::min(kRows, n - i);
    if (weighted) {
      chi2 += ChunkResiduals<true>(view.x + i, view.y + i, view.uy + i, m, model, e, z, block_max);
      log_u.Add(view.uy + i, m);
      scan(i, m, z, threshold, &report.outliers);
    } else {
      chi2 += ChunkResiduals<false>(view.x + i, view.y + i, nullptr, m, model, e, z, block_max);
      if (!candidates_complete) continue;
      scan(i, m, e, e_candidate, &candidates);
      if (candidates.size() > candidate_limit) candidates_complete = false;
    }
  }
  if (!weighted) {
    chi2 *= static_cast<long double>(view.sy) * view.sy;  // Σ residual² in Y's units (sy = 2^n)
    // Normalised residual r_i/s, s the residual standard deviation (none for an exact fit).
    model.sigma_common = n > 2 ? std::sqrt(static_cast<double>(chi2) / static_cast<double>(n - 2)) : 0.0;
    const auto flag = [&](std::size_t i) {
      if (internal::EvaluateRow(model, threshold, i, data.x[i], data.y[i], 0.0, 0.0).outlier)
        report.outliers.push_back(i);
    };
    if (model.sigma_common > 0.0) {
      if (candidates_complete)
        for (std::size_t i : candidates) flag(i);
      else
        for (std::size_t i = 0; i < n; ++i) flag(i);
    }
    if (!data.u_x.empty() || !data.u_y.empty())
      report.notes.push_back("OLS ignores the given uncertainties (use WLS or York)");
  } else if (!data.u_x.empty()) {
    report.notes.push_back("WLS ignores u(X) (York's fit uses it)");
  }
  if (options.keep_rows) {
    report.rows.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      report.rows.push_back(
          internal::EvaluateRow(model, threshold, i, data.x[i], data.y[i], 0.0, weighted ? data.u_y[i] : 0.0));
  }
  report.chi2 = static_cast<double>(chi2);
  // R² = 1 − χ²/Σ w (Y − Ȳ_w)², the total from the moments (standardised units).
  const double total = moments.yy - moments.y * moments.y / moments.w;
  const double chi2_standardised = weighted ? report.chi2 : report.chi2 / (view.sy * view.sy);
  if (total > 0) report.r_squared = 1.0 - chi2_standardised / total;
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), weighted, true);
  SetInformationCriteria(report, weighted ? static_cast<double>(2.0L * log_u.value()) : 0.0);
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
