// FitOptions: the knobs every fit shares.
//
// Every line fit is solved by Ceres (Levenberg-Marquardt, dense QR) on a standardised problem:
// X and Y are centred at a (weighted) mean and divided by a power of two near their spread, so
// that the tolerances below are relative, unit-free numbers and X ≈ 1e9 with a spread of 1 loses
// no digits: the subtraction X_i − x0 is the only rounding the data see (and it is exact when
// X_i and x0 are within a factor of 2, by Sterbenz's lemma); scaling by 2^e is exact.
//
// The tolerances default to "as tight as binary64 allows". Even so, Ceres' termination tests look
// at the cost, which is flat to ~sqrt(ε) relative at a minimum: Ceres stops when a step no longer
// changes the cost, with parameters good to ~1e-9 relative. Every fit therefore ends with a
// Gauss-Newton refinement on Ceres' own cost functions (for a robust loss, Newton's step), which
// stops where the step no longer shrinks: the gradient is accurate to ~ε, so the parameters are
// too. (York's fit, whose residuals are curved in the slope, polishes with Newton's step on the
// exact Hessian instead, which gets there in one step: york_line.hpp.) SolverInfo::
// refinement_steps counts the steps; a linear fit seeded with its closed form needs one or two,
// the second at the rounding level. From a cold start
// (seed_with_closed_form = false) Ceres plus the refinement reach NIST's certified values to
// ≥ 13 digits.
#pragma once

namespace uphill {

struct FitOptions {
  // |normalised residual| above this flags a row as an outlier (RowResult::outlier). 3 means
  // "beyond 3 sigma": about 0.27 % of rows for Gaussian errors, so a few flags among 10^3 rows
  // are expected, not alarming.
  double outlier_threshold = 3.0;
  // Start Ceres at the closed-form solution (Eigen QR of the centred design; York: the WLS line
  // in u(Y), which is York's criterion at slope 0). false starts at slope 0, intercept = weighted mean of Y
  // (friction: mu = 0), to show that Ceres on its own reaches the same values.
  bool seed_with_closed_form = true;
  // Ceres termination (Solver::Options of the same names). gradient_tolerance is absolute in
  // Ceres, hence 0 here: only the relative tests below end the solve. 1e-14 (45 ε) rather than
  // 1e-15: with 10^6 rows the rounding noise of the cost is ~sqrt(N)·ε relative, and a tighter
  // function tolerance only buys Ceres steps that chase that noise (the refinement described
  // above, not the tolerance, sets the final precision). Invalid values: InputError.
  int max_iterations = 200;
  double function_tolerance = 1e-14;
  double gradient_tolerance = 0.0;
  double parameter_tolerance = 1e-14;
  // Fill FitReport::rows (one RowResult per input row). The line fits compute every row's
  // residual and normalised residual either way (χ², the outlier and down-weighted lists need
  // them); false leaves them unstored, for callers with many rows, who read them on demand through
  // LineRowResults (line_rows.hpp): the same numbers, without holding 56 bytes per row.
  bool keep_rows = true;
};

}  // namespace uphill
