// Fitting a straight line Y = k·X + c to X-Y data: the use case of `uphill fit --xy` (docs/fit.md),
// Python's uphill.fit_xy and fit_ols / fit_wls / fit_york / fit_robust, and the page's
// POST /api/fit-xy. Every front end parses the method's name and runs the fit here, so that a name
// means the same fit, with the same options, everywhere.
//
// Methods (fit/*.hpp): ols (ordinary least squares, the seed paper's fit), wls (weighted by u(Y)),
// york (errors in both variables, York et al. 2004), robust (Huber's or Cauchy's loss). The
// friction model is not a line fit: it needs the scenes of an experiment (report/analysis.hpp).
//
// Units: X, Y and their uncertainties are plain numbers, X and u(X) in one unit, Y and u(Y) in one
// unit; the report's k is in Y's unit per X's unit, c in Y's unit.
// Accuracy: that of the fits (NIST StRD Norris to 12.8-15.5 digits for ols: fit/least_squares_line.hpp).
// Errors: InputError naming the value as the fit layer does ("Y[3]", "u(Y)[0]", "rows") for data a
// method cannot use; the front end maps the index to its own row (a file's row, an array's element).
#pragma once

#include <string>

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"
#include "fit/robust_line.hpp"

namespace uphill {

// The method a front end uses when none is named.
inline constexpr const char* kDefaultFitXyMethod = "ols";

// "ols", "wls", "york" or "robust". Throws InputError(quantity, "must be ols, wls, york or robust
// (got '<name>')"): `quantity` is the front end's name for the choice ("--method", "method").
FitMethod ParseFitMethod(const std::string& name, const std::string& quantity = "method");

struct FitXyOptions {
  FitOptions fit;                         // outlier threshold, keep_rows, solver tolerances
  RobustLoss loss = RobustLoss::kHuber;   // robust only
  double loss_scale = 0.0;                // robust only: δ in units of σ; 0 = the loss's default
};

// The fit of `method` (a line method; kFriction throws InputError("method")) to `data`, with the
// method's own use of the uncertainty columns (fit/line_data.hpp: ols ignores them with a note,
// wls needs u(Y), york u(X) and u(Y), robust uses u(Y) when given).
FitReport FitXy(FitMethod method, const LineData& data, const FitXyOptions& options = {});

}  // namespace uphill
