// The rolling-resistance model fitted to the measured farthest rest positions.
//
// Model (docs/physics.md "Rolling resistance"): the body stays at rest where
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
// scene: York's line with u(X) = u_model and u(Y) when u_model is given, so that both models see
// the same uncertainties - York's σ_i² = u(Y)² + k²u(X)² equals the friction fit's for k = 1 and
// is within a few % of it for the lab's k ≈ 1; else WLS when u(Y) is given, else OLS) and
// compares χ², AIC and BIC.
//
// σ_i = u(Y_i) when given (then primary_scaling = kUnscaled, p-value reported); otherwise σ = 1
// in metres for the unscaled covariance and the usual scaled errors are primary, as for OLS.
//
// Errors in the model value (u_model). In an experiment the model value x_rest,i(μ) is itself
// uncertain: it is computed from the measured L, H, D (and the body's dimensions), and their
// errors move it as surely as the measurement error moves Y. With u_model given, the fit uses
// the effective variance σ_i² = u(Y_i)² + u_model,i² (the friction analogue of York's
// u(Y)² + k²u(X)² with k = 1: Y = x_rest(μ) has unit slope in x_rest). Without it, χ²/ν
// of lab data is inflated by the model's scatter and σ_μ is too small.
// u_model is supplied by the caller and held fixed (independent of μ). AnalyseExperiment
// passes u(X) = u(x_eq) from the first-order propagation of the inputs' uncertainties
// (model/propagation.hpp): an approximation of u(x_rest(μ̂)), good because ∂x_rest/∂input ≈
// ∂x_eq/∂input while μ is small against tanθ (x_rest depends on μ only through
// K = tanθ + μ(1 + A²)). For the lab's settings (θ ≈ 14°, D 100-200 mm, u(L) = 1 mm,
// u(D) = 0.2 mm) u(x_rest(μ))/u(x_eq) is within 0.1 % of 1 up to μ = 0.05 (central differences),
// and the pull test in tests/fit_friction_test.cpp shows σ_μ covering. Why fixed and
// not propagated to x_rest(μ̂) here: FrictionData holds scenes (angles), not the measured inputs
// and their uncertainties; propagating inside the fit would need those (a possible extension:
// per-row input uncertainties, then σ_i(μ) by ceres::Jet through the same closed forms).
// Rows with correlated model errors (several trials of one setting share its L, D errors) are
// still treated as independent: χ² then describes the scatter, the covariance is optimistic by
// up to sqrt(trials per setting) when u_model dominates.
// Parameters "mu" (dimensionless) and, with fit_scale, "s". If μ ends at its bound 0 a note says
// so: the covariance is then that of the unconstrained problem (a one-sided statement μ ≤ σ_μ
// is the honest reading).
//
// Errors (InputError): no rows or fewer rows than parameters; y/u_y/u_model not matching the
// scenes; non-finite Y; u(Y) ≤ 0; u_model not finite or < 0, or given without u_y; a double cone (constant slope: no rest position to fit); rows that
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
  // Standard uncertainty of the model value x_rest,i at row i, m (finite, ≥ 0), from the
  // inputs' uncertainties (see above), or empty = none. Needs u_y.
  std::vector<double> u_model;

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
