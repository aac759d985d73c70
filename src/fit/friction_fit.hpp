// The rolling-resistance model fitted to the measured farthest rest positions.
//
// Model (PHYSICS.md, "Rolling resistance as a slope threshold"): the body stays at rest where
// |z'(x)| ≤ μ, so the farthest rest position of row i is x_rest,i(μ) = Scene_i.Rest(μ)->high; for
// line rails x_rest(μ) = x_max·K/sqrt(P·A² + K²), K = B + μ(1 + A²). The fit is
//     Y_i = s·x_rest,i(μ),   μ ≥ 0,   s = 1 unless fit_scale (then s is a free scale factor that
//                                       absorbs a common calibration error of the Y scale),
// by Ceres with the bound μ ≥ 0 (Problem::SetParameterLowerBound). Derivatives: automatic
// (SpheroidOnLineRails<ceres::Jet>, the model's own closed form) for spheres and spheroids on
// line rails and spheres on rods (a sphere of radius R + r on the rod axes); central numeric
// differences (ceres::NumericDiffCostFunction, SpheroidOnRods::RestX) for spheroids on rods,
// the one case without a closed form. Before fitting, every row's x_rest at the start value is
// checked against Scene::Rest, so the fit and the model cannot drift apart.
//
// Friction predicts an offset Y − X that depends on θ, α and the body, not a constant intercept;
// CompareFrictionWithLine fits both models to the same rows (the line against X_i = x_eq of each
// scene, WLS when u(Y) is given, else OLS) and compares χ², AIC and BIC.
//
// σ_i = u(Y_i) when given (then primary_scaling = kUnscaled, p-value reported); otherwise σ = 1
// in metres for the unscaled covariance and the usual scaled errors are primary, as for OLS.
// Parameters "mu" (dimensionless) and, with fit_scale, "s". If μ ends at its bound 0 a note says
// so: the covariance is then that of the unconstrained problem (a one-sided statement μ ≤ σ_μ
// is the honest reading).
//
// Errors (InputError): no rows or fewer rows than parameters; y/u_y not matching the scenes;
// non-finite Y; u(Y) ≤ 0; a double cone (constant slope: no rest position to fit); rows that
// cannot determine μ and s (e.g. fit_scale with a single apparatus setting: singular covariance).
#pragma once

#include <optional>
#include <vector>

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/model_comparison.hpp"
#include "model/scene.hpp"

namespace uphill {

struct FrictionData {
  std::vector<Scene> scenes;  // one apparatus setting (body, rails, rods) per row
  std::vector<double> y;      // measured farthest rest position Y_i, m
  std::vector<double> u_y;    // u(Y_i), m, or empty

  std::size_t size() const { return scenes.size(); }
};

struct FrictionOptions {
  bool fit_scale = false;          // also fit s in Y = s·x_rest(μ)
  std::optional<double> mu_start;  // default: median of the per-row inversions of x_rest(μ) = Y
  FitOptions fit;
};

FitReport FitFriction(const FrictionData& data, const FrictionOptions& options = {});

struct FrictionVersusLine {
  FitReport friction;
  FitReport line;              // Y = k·x_eq + c on the same rows
  ModelComparison comparison;  // first = line, second = friction
};

FrictionVersusLine CompareFrictionWithLine(const FrictionData& data,
                                           const FrictionOptions& options = {});

}  // namespace uphill
