#include "fit/york_line.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "internal/compressed_cost.hpp"
#include "internal/line_problem.hpp"
#include "internal/log_sum.hpp"
#include "fit/model_comparison.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

using namespace internal;

// York's criterion in standardised coordinates (x, y, u(X)/sx, u(Y)/sy), θ = (k, c):
// r_i = e_i·sqrt(W_i), e_i = y_i − c − k·x_i, W_i = 1/(uy_i² + k²·ux_i²), with the analytic
// Jacobian ∂r_i/∂(k, c) = −sqrt(W_i)·(ξ_i, 1), ξ_i = x_i + k·ux_i²·W_i·e_i (the adjusted x of the
// header). Only sums reach Ceres (compressed_cost.hpp): Σ r² = Σ W e², Jᵀr = −Σ W e (ξ, 1),
// JᵀJ = Σ W (ξ, 1)ᵀ(ξ, 1), and for the Newton polish the exact Hessian of ½Σ r²,
//     JᵀJ + Σ q_i·[[2kξ_i − e_i + k²ux_i²W_i e_i, k], [k, 0]],   q_i = ux_i²·W_i²·e_i
// (differentiate ½Σ W e² twice; a wrong Hessian would only slow the polish down, since the
// result is checked by AtRoundingLevel).
// No square root and one division per row. One fused loop per chunk of rows standardises, forms
// W, e, ξ and adds the eight sums: `omp simd` (york_line.cpp is built with -fopenmp-simd, which
// enables only these directives, no OpenMP runtime) lets the compiler keep the sums in vector
// lanes - without it GCC must add in row order and cannot vectorise. The loops are also compiled
// for AVX2 (gnu::target_clones; the CPU picks at load time, baseline x86-64 otherwise). Measured
// per pass over 10^6 rows: Eigen array expressions, which store and reload every
// intermediate, 4.9 ms; the fused loop 2.3 ms (SSE2), 1.3 ms (AVX2). The lanes and the AVX2
// clone change only the order of additions (results agree to ~1e-16). Each chunk's sums are
// accumulated in long double: free per row, and the gradient's rounding stays at the level of
// one chunk's sum.
constexpr std::size_t kRows = 1024;  // per chunk of the fused loops (16 KB of each column)

struct Constants {
  double x0, y0, inv_sx, inv_sy;
};

// One row's contributions at θ = (k, c) (see above), from the raw columns and the constants
// of the standardisation. A value-returning function so that `omp simd` sees plain reductions.
struct Terms {
  double w, wxi, wxi2, we, wexi, wee, q, qh, e, var;
};
template <bool kNewton>
inline Terms RowTerms(double x, double y, double ux, double uy, double x0, double y0, double isx,
                      double isy, double k, double c) {
  const double xs = (x - x0) * isx;  // exact scaling: isx is a power of two
  const double e = (y - y0) * isy - c - k * xs;
  const double uxs = ux * isx, uys = uy * isy;
  const double ux2 = uxs * uxs;
  const double var = uys * uys + k * k * ux2;
  const double w = 1.0 / var;
  const double we = w * e;
  const double xi = xs + k * ux2 * we;
  Terms t{w, w * xi, w * xi * xi, we, we * xi, we * e, 0.0, 0.0, e, var};
  if constexpr (kNewton) {
    t.q = ux2 * w * we;
    t.qh = t.q * (2.0 * k * xi - e + k * k * ux2 * we);
  }
  return t;
}

class YorkCost final : public CompressedLineCost {
 public:
  explicit YorkCost(const StandardisedView& v) : v_(v), q_{v.x0, v.y0, v.inv_sx, v.inv_sy} {}

  // Per-row results at θ, in the same pass as the sums there (remembered for the covariance).
  struct RowPass {
    long double chi2 = 0, sum_log_sigma2 = 0;
  };
  // keep_rows: also store the rows in report->rows (FitOptions::keep_rows).
  RowPass Rows(const double* theta, double outlier_threshold, bool keep_rows, FitReport* report) const;

 private:
  bool RowSums(const double* theta, bool with_hessian, LineSums* sums) const override {
    long double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < v_.n; i += kRows) {
      const std::size_t m = std::min(kRows, v_.n - i);
      if (with_hessian)
        ChunkSums<true>(i, m, theta[0], theta[1], acc);
      else
        ChunkSums<false>(i, m, theta[0], theta[1], acc);
    }
    ToSums(acc, theta[0], with_hessian, sums);
    return true;
  }

  // What the per-row results need of a chunk: e_i, σ_i = sqrt(uy² + k²ux²), e_i/σ_i, and
  // Σ ln σ_i² (log_sum.hpp: no log per row). The same formulas as row_model.hpp's York rows.
  struct RowOut {
    double *e, *sigma, *z, *var;
    LogSum log_var;
  };

  // Adds the chunk's sums to acc (the Newton terms when kNewton). Not inlined, nor is
  // ChunkRows: GCC 12 vectorises these loops on their own but not always once inlined.
  template <bool kNewton>
  [[gnu::noinline, gnu::target_clones("avx2", "default")]] void ChunkSums(
      std::size_t i, std::size_t m, double k, double c, long double acc[8]) const {
    const double *x = v_.x + i, *y = v_.y + i, *ux = v_.ux + i, *uy = v_.uy + i;
    const double x0 = q_.x0, y0 = q_.y0, isx = q_.inv_sx, isy = q_.inv_sy;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5, s6, s7)
    for (std::size_t j = 0; j < m; ++j) {
      const Terms t = RowTerms<kNewton>(x[j], y[j], ux[j], uy[j], x0, y0, isx, isy, k, c);
      s0 += t.w, s1 += t.wxi, s2 += t.wxi2, s3 += t.we, s4 += t.wexi, s5 += t.wee;
      if constexpr (kNewton) s6 += t.q, s7 += t.qh;
    }
    acc[0] += s0, acc[1] += s1, acc[2] += s2, acc[3] += s3;
    acc[4] += s4, acc[5] += s5, acc[6] += s6, acc[7] += s7;
  }

  // ChunkSums<false> plus the per-row quantities of RowOut.
  [[gnu::noinline, gnu::target_clones("avx2", "default")]] void ChunkRows(
      std::size_t i, std::size_t m, double k, double c, long double acc[8], RowOut* out) const {
    const double *x = v_.x + i, *y = v_.y + i, *ux = v_.ux + i, *uy = v_.uy + i;
    const double x0 = q_.x0, y0 = q_.y0, isx = q_.inv_sx, isy = q_.inv_sy;
    double *e_out = out->e, *sigma_out = out->sigma, *z_out = out->z, *var_out = out->var;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5)
    for (std::size_t j = 0; j < m; ++j) {
      const Terms t = RowTerms<false>(x[j], y[j], ux[j], uy[j], x0, y0, isx, isy, k, c);
      s0 += t.w, s1 += t.wxi, s2 += t.wxi2, s3 += t.we, s4 += t.wexi, s5 += t.wee;
      const double root_w = std::sqrt(t.w);  // t.w = 1/var, as row_model.hpp
      e_out[j] = t.e;
      var_out[j] = t.var;
      sigma_out[j] = t.var * root_w;  // sqrt(var) to an ulp or two, without a second division
      z_out[j] = t.e * root_w;
    }
    acc[0] += s0, acc[1] += s1, acc[2] += s2, acc[3] += s3;
    acc[4] += s4, acc[5] += s5;
    out->log_var.Add(var_out, m);
  }

  static void ToSums(const long double acc[8], double k, bool with_hessian, LineSums* s) {
    const double sw = static_cast<double>(acc[0]), swxi = static_cast<double>(acc[1]),
                 swxi2 = static_cast<double>(acc[2]);
    s->jtj << swxi2, swxi, swxi, sw;
    s->jtr << -static_cast<double>(acc[4]), -static_cast<double>(acc[3]);
    s->rr = static_cast<double>(acc[5]);
    const double q = static_cast<double>(acc[6]);
    s->hessian = s->jtj;
    if (!with_hessian) return;
    s->hessian(0, 0) += static_cast<double>(acc[7]);
    s->hessian(0, 1) += k * q;
    s->hessian(1, 0) += k * q;
  }

  StandardisedView v_;
  Constants q_;
};

YorkCost::RowPass YorkCost::Rows(const double* theta, double outlier_threshold, bool keep_rows,
                                 FitReport* report) const {
  RowPass out;
  long double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  double e[kRows], sigma[kRows], z[kRows], var[kRows];
  RowOut chunk{e, sigma, z, var, {}};
  const double sy = v_.sy;
  RowResults& rows = report->rows;
  rows.clear();
  if (keep_rows) rows.reserve(v_.n);  // written once, below (resize would write every row twice)
  for (std::size_t i = 0; i < v_.n; i += kRows) {
    const std::size_t m = std::min(kRows, v_.n - i);
    ChunkRows(i, m, theta[0], theta[1], acc, &chunk);
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t index = i + j;
      const bool outlier = std::abs(z[j]) > outlier_threshold;
      if (keep_rows) {
        const double residual = sy * e[j];  // exact: sy = 2^n
        rows.push_back(RowResult{index, v_.y[index] - residual, residual, sy * sigma[j], z[j], 1.0, outlier});
      }
      if (outlier) report->outliers.push_back(index);
    }
  }
  LineSums sums;
  ToSums(acc, theta[0], false, &sums);
  Remember(theta, sums, false);
  out.chi2 = acc[5];
  // ln σ_i² = ln σ_s² + 2 ln sy.
  out.sum_log_sigma2 = chunk.log_var.value() + 2.0L * static_cast<long double>(v_.n) *
                                               std::log(static_cast<long double>(sy));
  return out;
}

// A Newton step this small (relative) is taken without a pass of its own: the rows' pass checks
// the result (AtRoundingLevel).
constexpr double kUnverifiedStep = 1e-6;

// Whether the Gauss-Newton step at θ (from the sums of the rows' pass) is at the rounding level
// of the standardised problem (|θ| is O(1) or less there, and the gradient's rounding moves the
// step by ~1e-16): then θ is York's line to the accuracy binary64 allows.
bool AtRoundingLevel(const LineSums* sums, const Eigen::Vector2d& theta) {
  if (!sums) return false;
  const Eigen::Vector2d step = sums->jtj.ldlt().solve(-sums->jtr);
  return step.allFinite() && step.norm() <= 1e-13 * std::max(1.0, theta.norm());
}

}  // namespace

FitReport FitErrorsInVariables(const LineData& data, const FitOptions& options) {
  const StandardisedView view = ValidateAndView(data, UncertaintyUse::kXY, "York's fit");
  const std::size_t n = data.size();

  ceres::Problem problem;  // owns the cost function
  auto* cost = new YorkCost(view);
  Eigen::Vector2d theta = Eigen::Vector2d::Zero();
  if (options.seed_with_closed_form) {
    // The WLS line in u(Y) (York's criterion at k = 0 is WLS; a Gauss-Newton step from 0 is
    // its closed form).
    const LineSums* at_zero = cost->Sums(theta.data());
    if (at_zero) theta = at_zero->jtj.ldlt().solve(-at_zero->jtr);
    if (!theta.allFinite()) theta.setZero();  // degenerate data: let Ceres start cold
  }
  problem.AddResidualBlock(cost, nullptr, theta.data());

  FitReport report = StartReport(FitMethod::kErrorsInVariables, n, true, ErrorScaling::kUnscaled,
                                 options.outlier_threshold);
  report.solver = RunCeres(options, options.seed_with_closed_form, &problem);
  // Newton's polish; its last step (< 1e-6 relative) is checked by the rows' pass below.
  report.solver.refinement_steps = RefineNewton(*cost, theta.data(), kUnverifiedStep);

  YorkCost::RowPass pass = cost->Rows(theta.data(), options.outlier_threshold, options.keep_rows, &report);
  if (!AtRoundingLevel(cost->Sums(theta.data()), theta)) {
    // Not yet at the minimum to rounding: polish with checked steps, and redo the rows.
    report.outliers.clear();
    report.solver.refinement_steps += RefineNewton(*cost, theta.data());
    pass = cost->Rows(theta.data(), options.outlier_threshold, options.keep_rows, &report);
  }
  const auto covariance_theta = CeresCovariance(&problem, theta.data(), 2);
  if (!covariance_theta)
    throw InputError("X",
                     "the values are too close together for a slope in binary64 "
                     "(rank-deficient design)");
  const Standardisation s{view.x0, view.y0, view.sx, view.sy};
  const LineParameters line = Unstandardise(s, theta, *covariance_theta);
  report.covariance = line.covariance;
  report.chi2 = static_cast<double>(pass.chi2);
  LineRowModel& model = report.row_model;
  model.valid = true;
  model.x0 = view.x0, model.y0 = view.y0, model.inv_sx = view.inv_sx, model.inv_sy = view.inv_sy;
  model.sy = view.sy, model.k = theta(0), model.c = theta(1);
  model.sigma = LineRowModel::Sigma::kYork;
  if (std::all_of(data.u_x.begin(), data.u_x.end(), [](double u) { return u == 0.0; }))
    report.notes.push_back("all u(X) are 0: York's line is the WLS line");
  FinishReport(report, {"k", "c"}, Eigen::Vector2d(line.k, line.c), true, true);
  SetInformationCriteria(report, static_cast<double>(pass.sum_log_sigma2));
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace uphill
