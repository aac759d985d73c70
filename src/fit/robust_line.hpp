// A robust straight line: minimise Σ ρ((r_i/σ_i)²) with Huber's or Cauchy's loss
// (ceres::HuberLoss / ceres::CauchyLoss; one residual block per row, since Ceres applies a loss
// to a whole block), so that a few gross errors do not drag the line.
//
// σ_i: u(Y_i) when given (finite, > 0); otherwise one robust scale for all rows,
// σ = 1.4826·MAD of the residuals (the MAD of Gaussian data estimates σ; 1.4826 = 1/Φ⁻¹(3/4)),
// first of the least-squares residuals, then - since a gross error drags the least-squares
// line and inflates them - of the robust residuals, until σ is a fixed point (to 1e-12; Huber's
// "proposal 2" in spirit). If more than half the rows lie exactly on the line (MAD = 0) the
// residual SD is used. u(X) is ignored.
//
// loss_scale δ (in units of σ): where the loss turns from quadratic to linear (Huber) or where
// a row's influence starts to fall (Cauchy). Defaults give 95 % efficiency at Gaussian errors:
// Huber 1.345, Cauchy 2.3849. Cauchy is not convex, so it starts from the Huber solution.
//
// Solving: seeded (the default), Newton steps on the Huber objective from the least-squares
// line (exact in a few O(N) steps for a piecewise-quadratic loss), the σ iteration, then Ceres
// on the final loss from there; cold (seed_with_closed_form = false), Ceres from slope 0.
// Both end in the same refinement (fit_options.hpp) and agree to ~1e-12.
//
// Weights and down-weighted rows: each row's weight is ρ'(s_i), s_i = (r_i/σ_i)², the factor
// by which its influence is reduced relative to least squares (Huber: min(1, δ/|r_i/σ_i|);
// Cauchy: 1/(1 + s_i/δ²)). A row is reported in FitReport::downweighted when
// |r_i/σ_i| > δ, i.e. beyond the loss scale: Huber weight < 1, Cauchy weight < 1/2.
//
// Covariance: ceres::Covariance with the loss applied, which for ρ'' ≤ 0 (both losses here) is
// the weighted least-squares covariance at the final weights, (Σ w_i x_i x_iᵀ/σ_i²)⁻¹ - the usual
// IRLS approximation (it ignores the randomness of the weights). chi2 = Σ w_i (r_i/σ_i)²; scaled
// covariance = unscaled × chi2/ν. No p-value and no AIC/BIC (the loss is not a Gaussian
// likelihood). Primary scaling: unscaled.
//
// Cost: one residual block per row, so Ceres' bookkeeping is ~300 bytes per row, and Problem
// construction, Solve's preprocessing and ceres::Covariance each cost a pass over all blocks.
#pragma once

#include "fit/fit_options.hpp"
#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

enum class RobustLoss { kHuber, kCauchy };

struct RobustOptions {
  RobustLoss loss = RobustLoss::kHuber;
  double loss_scale = 0.0;  // δ in units of σ; 0 = the default of the loss (1.345 / 2.3849)
  FitOptions fit;
};

FitReport FitRobust(const LineData& data, const RobustOptions& options = {});

}  // namespace uphill
