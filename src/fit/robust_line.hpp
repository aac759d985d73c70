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
// Solving: Ceres (Levenberg-Marquardt) on the robust objective, seeded (the default) from the
// least-squares line, cold (seed_with_closed_form = false) from slope 0; then Newton steps with the
// exact Hessian (exact in a step or two for Huber's piecewise-quadratic loss). Ceres sees the N
// rows compressed to 3 residuals whose cost is Σρ and whose Jacobian carries the IRLS matrix
// Σ ρ'·JᵢᵀJᵢ (internal/compressed_cost.hpp, as York's fit): one vectorised pass over the rows per
// evaluation, no per-row residual blocks. Without u(Y) each new σ is a new solve from the last
// line. Both starts agree to ~1e-12.
// Weights and down-weighted rows: each row's weight is ρ'(s_i), s_i = (r_i/σ_i)², the factor
// by which its influence is reduced relative to least squares (Huber: min(1, δ/|r_i/σ_i|);
// Cauchy: 1/(1 + s_i/δ²)). A row is reported in FitReport::downweighted when
// |r_i/σ_i| > δ, i.e. beyond the loss scale: Huber weight < 1, Cauchy weight < 1/2.
//
// Covariance: ceres::Covariance of the compressed problem, the weighted least-squares covariance
// at the final weights, (Σ w_i x_i x_iᵀ/σ_i²)⁻¹ - the usual IRLS approximation (it ignores the
// randomness of the weights); for ρ'' ≤ 0 (both losses here) also what Ceres' robustified
// covariance of the N-row problem gives. chi2 = Σ w_i (r_i/σ_i)²; scaled
// covariance = unscaled × chi2/ν. No p-value and no AIC/BIC (the loss is not a Gaussian
// likelihood). Primary scaling: unscaled.
//
// Accuracy: against Newton's iteration on the same objective in long double (src/oracle,
// tests/fit_robust_test.cpp, tests/fit_oracle_test.cpp): ≤ 1e-13 relative in k, c and ≤ 1e-12 in the covariance with u(Y); with
// the estimated σ ≤ 1e-12. Cost: O(N) per Ceres iteration or Newton step (typically under 10),
// plus, without u(Y), a median (nth_element) per σ round. Per-row results: FitOptions::keep_rows
// and line_rows.hpp.
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
