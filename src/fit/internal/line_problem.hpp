// Internal to the fit layer (not installed, not for callers): what all fits share - the
// standardised data, the closed-form seed, running Ceres, ceres::Covariance, and filling the
// common statistics of a FitReport.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill::internal {

// 2^e with 2^e ≤ v < 2^(e+1), v > 0 finite: scaling by it is exact in binary.
double PowerOfTwoBelow(double v);

// Standardised coordinates: X = x0 + sx·x, Y = y0 + sy·y, sx and sy powers of two near the
// largest deviation, so that the only rounding is that of X_i − x0 and Y_i − y0.
struct Standardisation {
  double x0 = 0.0, y0 = 0.0, sx = 1.0, sy = 1.0;
};

// A FitReport with what every line fit sets before solving.
FitReport StartReport(FitMethod method, std::size_t n, bool uses_stated_uncertainties,
                      ErrorScaling primary_scaling, double outlier_threshold);

// The standardised coordinates without copying the data: the fits standardise X and Y on the
// fly in their row loops ((X_i − x0)·(1/sx) with 1/sx an exact power of two), so no N-sized
// buffer is allocated.
// x0, y0 are plain means (one vectorised pass, which also finds the extremes for sx, sy and
// the range of u(Y)/sy); any centre inside the data's range keeps X_i − x0 exact when the
// data sit far from 0 (Sterbenz), and the fits' results do not depend on it beyond rounding.
// Throws InputError (RequireRepresentable's) when u(Y)/sy is out of binary64 range.
struct StandardisedView {
  double x0 = 0.0, y0 = 0.0, sx = 1.0, sy = 1.0, inv_sx = 1.0, inv_sy = 1.0;
  const double *x = nullptr, *y = nullptr, *ux = nullptr, *uy = nullptr;  // the raw columns
  std::size_t n = 0;
};
StandardisedView ViewStandardised(const LineData& data, bool use_ux, bool use_uy);

// ValidateLineData and ViewStandardised in one vectorised scan of each column (sum, extremes):
// the common case, valid data, costs one read of the data; invalid data get ValidateLineData's
// message naming the row. u(X) is viewed for kXY, u(Y) for kY, kXY and (when given) kOptionalY.
StandardisedView ValidateAndView(const LineData& data, UncertaintyUse use, const std::string& method);

// Throws InputError for invalid options (outlier threshold ≤ 0, invalid Ceres settings).
void ValidateFitOptions(const FitOptions& options);

// Ceres' Levenberg-Marquardt with the options' tolerances, silent, one thread. Throws
// std::runtime_error if Ceres returns no usable solution.
SolverInfo RunCeres(const FitOptions& options, bool seeded, ceres::Problem* problem);

// Gauss-Newton refinement of one parameter block θ, repeated while the step shrinks; a step
// that raises the cost beyond rounding is undone. `costs` are the cost functions of the problem
// (each with θ as its only parameter block), evaluated directly (CostFunction::Evaluate: the
// same autodiff/numeric code Ceres uses, without Problem::Evaluate's per-call setup, which
// walks every residual block). Why: Ceres' termination tests look at the cost,
// which is flat to ~sqrt(ε) relative at a minimum, so Ceres stops with parameters good to
// ~1e-9; the gradient Jᵀr is accurate to ~ε (summed in long double), and so is its zero.
// With a robust loss (applied to each cost function's squared norm s, as Ceres does) the step
// is Newton's on Σ ρ(s_b)/2: H = Σ ρ'·JᵀJ + 2ρ''·(Jᵀr)(Jᵀr)ᵀ, g = Σ ρ'·Jᵀr - exact in a few
// steps for Huber's piecewise-quadratic loss, where the IRLS step (H = Σ ρ'·JᵀJ, Ceres' model)
// only converges linearly; IRLS is the fallback when H is not positive definite.
// lower_bound_0 keeps θ0 ≥ bound (then only the other parameters move). Returns the number of
// steps taken.
int RefineGaussNewton(const std::vector<const ceres::CostFunction*>& costs, double* block, int size,
                      std::optional<double> lower_bound_0 = std::nullopt,
                      const ceres::LossFunction* loss = nullptr);

// ceres::Covariance of one parameter block of `size` (apply_loss_function as given). nullopt
// when the Jacobian is rank deficient (Ceres' reciprocal condition number test).
std::optional<Eigen::MatrixXd> CeresCovariance(ceres::Problem* problem, const double* block,
                                               int size, bool apply_loss_function = true);

// Slope and intercept in data units from standardised (slope, intercept) and their covariance.
struct LineParameters {
  double k = 0.0, c = 0.0;
  Eigen::Matrix2d covariance;  // of (k, c)
};
LineParameters Unstandardise(const Standardisation& s, const Eigen::Vector2d& theta,
                             const Eigen::Matrix2d& covariance_theta);

// Throws InputError unless every standardised uncertainty can be squared and inverted in binary64
// (u must not be below ~1e-150 times the spread of the data).
void RequireRepresentable(const std::vector<double>& standardised_u, const std::string& quantity);

double UpperTailChiSquared(double chi2, int dof);

// Fills parameters (with both standard errors), covariance_scaled, correlation, dof,
// reduced_chi2, p_value (when p_value_applies), exact (+ note), the per-row outlier flags and
// the outlier list. Expects method, n, chi2, covariance, rows, outlier_threshold set.
// rows_flagged: the caller has set the rows' outlier flags and the outlier list itself (in its
// own pass over the rows), so FinishReport does not walk the rows again.
void FinishReport(FitReport& report, const std::vector<std::string>& names,
                  const Eigen::VectorXd& values, bool p_value_applies, bool rows_flagged = false);


}  // namespace uphill::internal
