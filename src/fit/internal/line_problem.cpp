#include "line_problem.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "model/solver_logs.hpp"

namespace uphill::internal {

double PowerOfTwoBelow(double v) {
  int e = 0;
  std::frexp(v, &e);  // v = f·2^e, f ∈ [0.5, 1)
  return std::ldexp(1.0, e - 1);
}

FitReport StartReport(FitMethod method, std::size_t n, bool uses_stated_uncertainties,
                      ErrorScaling primary_scaling, double outlier_threshold) {
  FitReport report;
  report.method = method;
  report.n = n;
  report.uses_stated_uncertainties = uses_stated_uncertainties;
  report.primary_scaling = primary_scaling;
  report.outlier_threshold = outlier_threshold;
  return report;
}

namespace {

// Sum (long double), extremes and the smallest positive value of a column, in one vectorised
// pass (this file is built with -fopenmp-simd). A NaN makes the sum NaN.
struct ColumnScan {
  long double sum = 0;
  double min = std::numeric_limits<double>::infinity(), max = -std::numeric_limits<double>::infinity();
  double min_positive = std::numeric_limits<double>::infinity();
};

[[gnu::noinline, gnu::target_clones("avx2", "default")]] void ScanChunk(const double* v, std::size_t m,
                                                                       ColumnScan* scan) {
  double sum = 0, lo = scan->min, hi = scan->max, lo_positive = scan->min_positive;
  const double inf = std::numeric_limits<double>::infinity();
#pragma omp simd reduction(+ : sum) reduction(min : lo, lo_positive) reduction(max : hi)
  for (std::size_t j = 0; j < m; ++j) {
    sum += v[j];
    lo = v[j] < lo ? v[j] : lo;
    hi = v[j] > hi ? v[j] : hi;
    const double positive = v[j] > 0.0 ? v[j] : inf;
    lo_positive = positive < lo_positive ? positive : lo_positive;
  }
  scan->sum += sum;
  scan->min = lo, scan->max = hi, scan->min_positive = lo_positive;
}

ColumnScan Scan(const std::vector<double>& v) {
  ColumnScan scan;
  constexpr std::size_t kRows = 1024;
  for (std::size_t i = 0; i < v.size(); i += kRows) ScanChunk(v.data() + i, std::min(kRows, v.size() - i), &scan);
  return scan;
}

// The bounds of line_data.cpp: values within ±1e100, uncertainties in [1e-100, 1e100] (or 0 where allowed).
constexpr double kLargest = 1e100, kSmallestUncertainty = 1e-100;

bool ValuesOk(const ColumnScan& s) {
  return std::isfinite(static_cast<double>(s.sum)) && s.min >= -kLargest && s.max <= kLargest;
}

bool UncertaintiesOk(const ColumnScan& s, bool zero_allowed) {
  if (!std::isfinite(static_cast<double>(s.sum)) || s.max > kLargest) return false;
  if (!zero_allowed) return s.min >= kSmallestUncertainty;
  return s.min >= 0.0 && (s.min_positive >= kSmallestUncertainty || !std::isfinite(s.min_positive));
}

// Power of two near the largest |v − centre| of [lo, hi], or near |centre| (or 1) when all equal it.
double ScaleOf(double lo, double hi, double centre) {
  const double largest = std::max(hi - centre, centre - lo);
  if (largest > 0.0 && std::isfinite(largest)) return PowerOfTwoBelow(largest);
  if (centre != 0.0) return PowerOfTwoBelow(std::abs(centre));
  return 1.0;
}

// The view from the columns' scans (u(Y)'s when use_uy).
StandardisedView ViewFromScans(const LineData& data, const ColumnScan& x, const ColumnScan& y, bool use_ux,
                               const ColumnScan* uy) {
  StandardisedView v;
  v.n = data.size();
  v.x = data.x.data();
  v.y = data.y.data();
  v.ux = use_ux ? data.u_x.data() : nullptr;
  v.uy = uy ? data.u_y.data() : nullptr;
  const long double n = static_cast<long double>(v.n);
  // The rounded mean lies within the data's range (clamped, should rounding push it out).
  v.x0 = std::clamp(static_cast<double>(x.sum / n), x.min, x.max);
  v.y0 = std::clamp(static_cast<double>(y.sum / n), y.min, y.max);
  v.sx = ScaleOf(x.min, x.max, v.x0);
  v.sy = ScaleOf(y.min, y.max, v.y0);
  v.inv_sx = 1.0 / v.sx;
  v.inv_sy = 1.0 / v.sy;
  // The covariance comes back from the standardised problem multiplied by sx² and sy²: a spread
  // below 1e-100 would underflow it to 0 (standard errors of inf or NaN).
  for (const auto& [scale, name] : {std::pair{v.sx, "X"}, std::pair{v.sy, "Y"}})
    if (scale < kSmallestUncertainty)
      throw InputError(name, std::string("its values spread over less than 1e-100 (") + ExactText(scale) +
                                 "): the fit's variances would underflow to 0; give the data in a smaller unit "
                                 "(larger numbers)");
  if (uy) {
    // u² and 1/u² are monotone in u: the extremes decide. Name the first offending row.
    const auto representable = [](double u) {
      const double u2 = u * u;
      return u2 > 0.0 && std::isfinite(u2) && std::isfinite(1.0 / u2);
    };
    if (!representable(uy->min * v.inv_sy) || !representable(uy->max * v.inv_sy)) {
      std::vector<double> scaled(data.u_y);
      for (double& u : scaled) u *= v.inv_sy;
      RequireRepresentable(scaled, "u(Y)");
    }
  }
  return v;
}

}  // namespace

StandardisedView ViewStandardised(const LineData& data, bool use_ux, bool use_uy) {
  const ColumnScan uy = use_uy ? Scan(data.u_y) : ColumnScan{};
  return ViewFromScans(data, Scan(data.x), Scan(data.y), use_ux, use_uy ? &uy : nullptr);
}

StandardisedView ValidateAndView(const LineData& data, UncertaintyUse use, const std::string& method) {
  const std::size_t n = data.x.size();
  const bool need_uy = use == UncertaintyUse::kY || use == UncertaintyUse::kXY ||
                       (use == UncertaintyUse::kOptionalY && !data.u_y.empty());
  const bool need_ux = use == UncertaintyUse::kXY;
  bool ok = data.y.size() == n && n >= 2 && (!need_uy || data.u_y.size() == n) && (!need_ux || data.u_x.size() == n);
  ColumnScan x, y, uy, ux;
  if (ok) {
    x = Scan(data.x);
    y = Scan(data.y);
    ok = ValuesOk(x) && ValuesOk(y) && x.min != x.max;
  }
  if (ok && need_uy) {
    uy = Scan(data.u_y);
    ok = UncertaintiesOk(uy, false);
  }
  if (ok && need_ux) {
    ux = Scan(data.u_x);
    ok = UncertaintiesOk(ux, true);
  }
  if (!ok) {
    ValidateLineData(data, use, method);  // names the row and the rule
    throw std::logic_error("ValidateAndView: the scan refused data that ValidateLineData accepts");
  }
  return ViewFromScans(data, x, y, need_ux, need_uy ? &uy : nullptr);
}

namespace {

ceres::Solver::Options SolverOptions(const FitOptions& options) {
  QuietSolverLogs();
  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // Dense QR of the N×p Jacobian: O(N·p²), accurate, and p ≤ 2 here.
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.num_threads = 1;  // the fits are cheap per row; threads would compete with callers
  solver.logging_type = ceres::SILENT;
  // See RunCeres (stationary start): enough invalid steps for the trust region to shrink to
  // min_trust_region_radius, which Ceres reports as CONVERGENCE, without an error log line.
  solver.max_num_consecutive_invalid_steps = 100;
  solver.minimizer_progress_to_stdout = false;
  return solver;
}

}  // namespace

void ValidateFitOptions(const FitOptions& options) {
  if (!(options.outlier_threshold > 0.0))
    throw InputError("outlier threshold",
                     "must be > 0 (got " + ExactText(options.outlier_threshold) + ")");
  if (std::string error; !SolverOptions(options).IsValid(&error)) throw InputError("fit options", error);
}

SolverInfo RunCeres(const FitOptions& options, bool seeded, ceres::Problem* problem) {
  ValidateFitOptions(options);
  const ceres::Solver::Options solver = SolverOptions(options);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, problem, &summary);
  // Started at a point that is stationary to rounding (a converged closed-form seed), every
  // trust-region step has a model cost change ≤ 0, which Ceres counts as an invalid step, and
  // after max_num_consecutive_invalid_steps it reports FAILURE with the start unchanged. That is
  // convergence (the Gauss-Newton model predicts no decrease anywhere), not a failure: accept it
  // when no step was taken and the cost is the finite start cost; the refinement that follows
  // every solve confirms it. (gradient_tolerance cannot catch it: it is absolute.)
  const bool stationary_start = summary.termination_type == ceres::FAILURE &&
                                summary.num_successful_steps == 0 &&
                                summary.message.find("invalid steps") != std::string::npos &&
                                std::isfinite(summary.initial_cost) &&
                                summary.final_cost == summary.initial_cost;
  if (!summary.IsSolutionUsable() && !stationary_start)
    throw std::runtime_error("Ceres found no usable solution: " + summary.message);
  SolverInfo info;
  info.converged = summary.termination_type == ceres::CONVERGENCE || stationary_start;
  info.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  info.seeded_with_closed_form = seeded;
  info.termination =
      stationary_start
          ? "CONVERGENCE: the start is stationary to rounding (Ceres: " + summary.message + ")"
          : std::string(ceres::TerminationTypeToString(summary.termination_type)) + ": " +
                summary.message;
  info.seconds = summary.total_time_in_seconds;
  return info;
}

namespace {

// Cost ½Σρ(s_b) and, with the Jacobian, the Newton and IRLS matrices and the gradient.
struct Normal {
  long double cost = 0;
  Eigen::MatrixXd newton, irls;
  std::vector<long double> gradient;
};

bool EvaluateAll(const std::vector<const ceres::CostFunction*>& costs, const double* block,
                 int size, const ceres::LossFunction* loss, bool with_jacobian, Normal* out) {
  out->cost = 0;
  if (with_jacobian) {
    out->newton = Eigen::MatrixXd::Zero(size, size);
    out->irls = Eigen::MatrixXd::Zero(size, size);
    out->gradient.assign(static_cast<std::size_t>(size), 0.0L);
  }
  std::vector<double> r, jacobian;
  std::vector<long double> jtr(static_cast<std::size_t>(size));
  Eigen::MatrixXd jtj(size, size);
  const double* parameters[1] = {block};
  for (const ceres::CostFunction* cost : costs) {
    const std::size_t m = static_cast<std::size_t>(cost->num_residuals());
    r.resize(m);
    if (with_jacobian) jacobian.resize(m * static_cast<std::size_t>(size));
    double* jacobians[1] = {jacobian.data()};
    if (!cost->Evaluate(parameters, r.data(), with_jacobian ? jacobians : nullptr)) return false;
    long double s = 0;
    for (double ri : r) s += static_cast<long double>(ri) * ri;
    double rho[3] = {static_cast<double>(s), 1.0, 0.0};
    if (loss) loss->Evaluate(static_cast<double>(s), rho);
    out->cost += 0.5L * rho[0];
    if (!with_jacobian) continue;
    // Jᵀr and JᵀJ of this block (row-major m×size Jacobian).
    std::fill(jtr.begin(), jtr.end(), 0.0L);
    jtj.setZero();
    for (std::size_t i = 0; i < m; ++i) {
      const double* row = &jacobian[i * static_cast<std::size_t>(size)];
      for (int a = 0; a < size; ++a) {
        jtr[static_cast<std::size_t>(a)] += static_cast<long double>(row[a]) * r[i];
        for (int b = 0; b <= a; ++b) jtj(a, b) += row[a] * row[b];
      }
    }
    for (int a = 0; a < size; ++a)
      for (int b = 0; b < a; ++b) jtj(b, a) = jtj(a, b);
    for (int a = 0; a < size; ++a) {
      out->gradient[static_cast<std::size_t>(a)] += rho[1] * jtr[static_cast<std::size_t>(a)];
      for (int b = 0; b < size; ++b) {
        out->irls(a, b) += rho[1] * jtj(a, b);
        out->newton(a, b) += rho[1] * jtj(a, b) +
                             2.0 * rho[2] * static_cast<double>(jtr[static_cast<std::size_t>(a)]) *
                                 static_cast<double>(jtr[static_cast<std::size_t>(b)]);
      }
    }
  }
  return std::isfinite(static_cast<double>(out->cost));
}

}  // namespace

int RefineGaussNewton(const std::vector<const ceres::CostFunction*>& costs, double* block, int size,
                      std::optional<double> lower_bound_0, const ceres::LossFunction* loss) {
  Eigen::Map<Eigen::VectorXd> theta(block, size);
  double previous_norm = std::numeric_limits<double>::infinity();
  int steps = 0;
  Normal here, there;
  if (!EvaluateAll(costs, block, size, loss, true, &here)) return 0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    Eigen::VectorXd g(size);
    for (int j = 0; j < size; ++j)
      g(j) = static_cast<double>(here.gradient[static_cast<std::size_t>(j)]);
    // Newton's matrix when it is positive definite, else the IRLS one (always ≥ 0).
    Eigen::LDLT<Eigen::MatrixXd> factor(here.newton);
    if (loss && !(factor.info() == Eigen::Success && (factor.vectorD().array() > 0.0).all()))
      factor.compute(here.irls);
    const Eigen::VectorXd start = theta;
    Eigen::VectorXd step = factor.solve(-g);
    if (lower_bound_0 && start(0) + step(0) < *lower_bound_0) {
      // θ0 stays on its bound; Gauss-Newton in the other parameters only.
      step.setZero();
      step(0) = *lower_bound_0 - start(0);
      if (size > 1)
        step.tail(size - 1) =
            here.irls.bottomRightCorner(size - 1, size - 1).ldlt().solve(-g.tail(size - 1));
    }
    if (!step.allFinite()) break;
    const double norm = step.norm();
    if (norm == 0.0 || !(norm < previous_norm)) break;  // at the rounding floor
    theta = start + step;
    if (norm <= 4.0 * std::numeric_limits<double>::epsilon() * start.norm()) {
      ++steps;  // a step at the rounding level cannot raise the cost: take it and stop
      break;
    }
    if (!EvaluateAll(costs, block, size, loss, true, &there) ||
        !(there.cost <= here.cost * (1.0L + 1e-12L) + std::numeric_limits<double>::min())) {
      theta = start;  // not a descent beyond rounding: keep the previous point
      break;
    }
    std::swap(here, there);
    ++steps;
    previous_norm = norm;
  }
  return steps;
}

std::optional<Eigen::MatrixXd> CeresCovariance(ceres::Problem* problem, const double* block,
                                               int size, bool apply_loss_function) {
  QuietSolverLogs();
  ceres::Covariance::Options options;
  // SVD of the dense N×p Jacobian (thin: O(N·p²) time, O(N·p) memory, p ≤ 2 here): 4× faster
  // than Eigen's sparse QR on 10^6 rows, and it reports rank deficiency (reciprocal condition
  // number below 1e-14) instead of returning garbage.
  options.algorithm_type = ceres::DENSE_SVD;
  options.num_threads = 1;
  options.apply_loss_function = apply_loss_function;
  ceres::Covariance covariance(options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{block, block}};
  if (!covariance.Compute(blocks, problem)) return std::nullopt;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(size, size);
  if (!covariance.GetCovarianceBlock(block, block, c.data())) return std::nullopt;
  return Eigen::MatrixXd(c);
}

LineParameters Unstandardise(const Standardisation& s, const Eigen::Vector2d& theta,
                             const Eigen::Matrix2d& covariance_theta) {
  // k = (sy/sx)·θ0;  c = y0 + sy·θ1 − k·x0. The intercept at the centre, y0 + sy·θ1, is
  // uncorrelated (or nearly) with k, so the x0²·var(k) term carries the ill-conditioning of c
  // for data far from X = 0 honestly and without cancellation.
  LineParameters p;
  const double ratio = s.sy / s.sx;
  p.k = ratio * theta(0);
  p.c = (s.y0 + s.sy * theta(1)) - p.k * s.x0;
  Eigen::Matrix2d jacobian;
  jacobian << ratio, 0.0, -ratio * s.x0, s.sy;
  p.covariance = jacobian * covariance_theta * jacobian.transpose();
  return p;
}

void RequireRepresentable(const std::vector<double>& standardised_u, const std::string& quantity) {
  for (std::size_t i = 0; i < standardised_u.size(); ++i) {
    const double u = standardised_u[i];
    const double u2 = u * u;
    if (!(u2 > 0.0) || !std::isfinite(u2) || !std::isfinite(1.0 / u2))
      throw InputError(quantity + "[" + std::to_string(i) + "]",
                       "is out of binary64 range relative to the spread of the data "
                       "(u/spread = " +
                           ExactText(u) + "); rescale the data");
  }
}

double UpperTailChiSquared(double chi2, int dof) {
  boost::math::chi_squared_distribution<double> distribution(dof);
  return boost::math::cdf(boost::math::complement(distribution, chi2));
}

void FinishReport(FitReport& report, const std::vector<std::string>& names,
                  const Eigen::VectorXd& values, bool p_value_applies, bool rows_flagged) {
  const int p = static_cast<int>(values.size());
  report.dof = static_cast<int>(report.n) - p;
  report.exact = report.dof == 0;
  // The last guard before any output: no inf or NaN leaves a fit. The inputs' bounds
  // (line_data.hpp) keep every case the tests know finite; a combination they miss is refused.
  if (!std::isfinite(report.chi2) || !values.allFinite() || !report.covariance.allFinite())
    throw InputError("rows", "the fit overflows binary64 for these values (chi2 = " + ExactText(report.chi2) +
                                 "): check for a value typed in the wrong unit, or rescale the data");
  if (report.dof > 0) {
    const double factor = report.chi2 / report.dof;
    report.reduced_chi2 = factor;
    report.covariance_scaled = report.covariance * factor;
    if (p_value_applies) report.p_value = UpperTailChiSquared(report.chi2, report.dof);
  }
  report.correlation = Eigen::MatrixXd::Identity(p, p);
  for (int i = 0; i < p; ++i)
    for (int j = 0; j < p; ++j)
      if (i != j) {
        const double d = std::sqrt(report.covariance(i, i) * report.covariance(j, j));
        report.correlation(i, j) = d > 0.0 ? report.covariance(i, j) / d : 0.0;
      }
  report.parameters.clear();
  for (int i = 0; i < p; ++i) {
    ParameterEstimate e;
    e.name = names[static_cast<std::size_t>(i)];
    e.value = values(i);
    e.se_unscaled = std::sqrt(report.covariance(i, i));
    if (report.covariance_scaled) e.se_scaled = std::sqrt((*report.covariance_scaled)(i, i));
    report.parameters.push_back(e);
  }
  if (!rows_flagged) {
    report.outliers.clear();
    for (RowResult& row : report.rows) {
      row.outlier = std::abs(row.normalised) > report.outlier_threshold;
      if (row.outlier) report.outliers.push_back(row.row);
    }
  }
  if (report.exact) {
    std::string note = "exact fit: " + std::to_string(report.n) + " rows determine the " +
                       std::to_string(p) +
                       " parameters (nu = 0), so no uncertainty can be estimated from the "
                       "scatter: reduced chi2, p-value and scaled standard errors are absent";
    note += report.uses_stated_uncertainties
                ? "; the unscaled standard errors are the stated uncertainties propagated"
                : "; without stated uncertainties the unscaled covariance assumes u(Y) = 1";
    report.notes.push_back(note);
  }
}

}  // namespace uphill::internal
