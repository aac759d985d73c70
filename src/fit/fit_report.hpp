// FitReport: what every fit returns - parameters, their covariance in both conventions,
// goodness of fit, and per-row diagnostics.
//
// Conventions (the same for all methods; see each method's header for its specifics):
//   covariance          "unscaled": (JᵀJ)⁻¹ of the normalised residuals r_i/σ_i at the solution,
//                       i.e. the stated uncertainties propagated to the parameters. Computed by
//                       ceres::Covariance. For a method without stated uncertainties (OLS, and
//                       the robust and friction fits when u(Y) is not given) σ_i = 1 in Y's
//                       units for OLS/friction, and the robust scale estimate for the robust fit.
//   covariance_scaled   unscaled × χ²/ν (the Birge-ratio / "external" convention): the scatter
//                       of the data decides the size of the errors. Absent when ν = 0.
//   primary_scaling     which of the two the method's literature calls "the" standard error:
//                       kScaled for OLS (the textbook s²(XᵀX)⁻¹, NIST's convention) and for the
//                       friction fit without u(Y); kUnscaled whenever stated uncertainties are
//                       used (WLS, York - York et al. 2004 report these; robust).
//   chi2                Σ (r_i/σ_i)² with the method's σ_i (OLS: the residual sum of squares, in
//                       Y units²; robust: Σ w_i (r_i/σ_i)², w_i the final robust weights).
//   reduced_chi2        χ²/ν, the MSWD; for OLS the residual variance s². Absent when ν = 0.
//   p_value             P(χ²_ν ≥ χ²), the upper tail (boost::math::chi_squared); present only
//                       when χ² is a sum of squares of stated-uncertainty-normalised residuals
//                       (WLS, York, friction with u(Y)) and ν > 0.
//   aic, bic            Gaussian information criteria (model_comparison.hpp).
//   exact               N equals the number of parameters (ν = 0): the model passes through the
//                       data, nothing can be said about the scatter; a note says so.
// Per row: residual r_i = Y_i − fitted_i, its σ_i, normalised residual r_i/σ_i, the robust
// weight (1 for non-robust fits) and the outlier flag |r_i/σ_i| > outlier_threshold.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fit/large_array_allocator.hpp"

namespace uphill {

enum class FitMethod {
  kOrdinaryLeastSquares,  // "ols"
  kWeightedLeastSquares,  // "wls"
  kErrorsInVariables,     // "york"
  kRobust,                // "robust"
  kFriction,              // "friction"
};
std::string MethodName(FitMethod method);

enum class ErrorScaling { kUnscaled, kScaled };

struct ParameterEstimate {
  std::string name;  // line fits: "k" (slope), "c" (intercept); friction: "mu", "s"
  double value = 0.0;
  double se_unscaled = 0.0;         // sqrt of the unscaled covariance diagonal
  std::optional<double> se_scaled;  // × sqrt(χ²/ν); absent when ν = 0
};

struct RowResult {
  std::size_t row = 0;      // index into the input
  double fitted = 0.0;      // the model at this row (line: c + k·X_i)
  double residual = 0.0;    // Y_i − fitted, computed from centred data (no cancellation)
  double sigma = 0.0;       // the σ_i that normalises it (0 for an exact OLS fit)
  double normalised = 0.0;  // residual/sigma (0 when sigma = 0)
  double weight = 1.0;      // robust weight ρ'(s_i) (1 for non-robust fits)
  bool outlier = false;     // |normalised| > outlier_threshold
};

// One RowResult per input row. A std::vector; its allocator puts arrays of ≥ 4 MiB (~75 000
// rows) in transparent huge pages, which makes large fits' per-row output cheap
// (large_array_allocator.hpp).
using RowResults = std::vector<RowResult, LargeArrayAllocator<RowResult>>;

// A row the robust fit trusts less than a plain least-squares fit would.
struct DownWeightedRow {
  std::size_t row = 0;
  double weight = 1.0;      // ρ'(s_i) ∈ (0, 1]: the row's weight relative to least squares
  double normalised = 0.0;  // its normalised residual
};

// How a straight-line fit's per-row results follow from its data, in the standardised coordinates
// the fit solved in (X = x0 + sx·x, Y = y0 + sy·y; sx, sy powers of two): set by the line fits,
// evaluated by LineRowResults (line_rows.hpp) and by the fits themselves, so both give the same
// numbers.
struct LineRowModel {
  bool valid = false;
  double x0 = 0.0, y0 = 0.0, inv_sx = 1.0, inv_sy = 1.0, sy = 1.0;
  double k = 0.0, c = 0.0;  // slope and intercept in standardised units
  // σ_i: one σ for all rows (OLS: the residual SD, 0 for an exact fit; robust without u(Y): the
  // robust scale), u(Y_i) (WLS; robust with u(Y)), or York's sqrt(u(Y_i)² + k²u(X_i)²).
  enum class Sigma { kCommon, kUy, kYork };
  Sigma sigma = Sigma::kCommon;
  double sigma_common = 0.0;  // kCommon: σ in Y's units
  // The robust weight ρ'(s_i) of the loss (1 for the non-robust fits), δ in units of σ.
  enum class Weight { kOne, kHuber, kCauchy };
  Weight weight = Weight::kOne;
  double loss_scale = 0.0;
};

struct SolverInfo {
  bool converged = false;  // Ceres terminated with CONVERGENCE
  int iterations = 0;      // Ceres iterations (successful and unsuccessful steps)
  bool seeded_with_closed_form = false;
  int refinement_steps = 0;  // Gauss-Newton steps after Ceres (see FitOptions)
  std::string termination;   // Ceres' termination type and message
  double seconds = 0.0;      // Ceres' total time (solve only)
};

struct FitReport {
  FitMethod method = FitMethod::kOrdinaryLeastSquares;
  std::vector<ParameterEstimate> parameters;
  Eigen::MatrixXd covariance;                        // unscaled
  std::optional<Eigen::MatrixXd> covariance_scaled;  // × χ²/ν; absent when ν = 0
  Eigen::MatrixXd correlation;                       // the same for both conventions
  ErrorScaling primary_scaling = ErrorScaling::kUnscaled;
  bool uses_stated_uncertainties = false;  // σ_i are the given u's (not estimated)

  std::size_t n = 0;  // rows
  int dof = 0;        // ν = n − number of parameters
  double chi2 = 0.0;
  std::optional<double> reduced_chi2;
  std::optional<double> p_value;
  std::optional<double> r_squared;  // OLS/WLS: 1 − Σw r²/Σw (Y − Ȳ_w)²
  std::optional<double> aic, bic;
  bool exact = false;

  double outlier_threshold = 3.0;
  RowResults rows;                            // empty when FitOptions::keep_rows is false
  LineRowModel row_model;                     // line fits: the rows on demand (line_rows.hpp)
  std::vector<std::size_t> outliers;          // rows with outlier = true, ascending
  std::vector<DownWeightedRow> downweighted;  // robust fit only, ascending row
  std::vector<std::string> notes;             // caveats in plain words (exact fit, bounds, ...)
  SolverInfo solver;

  // The parameter called `name`; throws std::out_of_range if there is none.
  const ParameterEstimate& Parameter(std::string_view name) const;
  // Line fits only (throw std::out_of_range otherwise).
  double slope() const { return Parameter("k").value; }
  double intercept() const { return Parameter("c").value; }
  // Standard error of parameter `name` in the given convention (absent: scaled with ν = 0).
  std::optional<double> StandardError(std::string_view name, ErrorScaling scaling) const;
  // The covariance in the method's primary convention (absent: scaled with ν = 0).
  std::optional<Eigen::MatrixXd> PrimaryCovariance() const;
};

}  // namespace uphill
