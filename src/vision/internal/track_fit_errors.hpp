// Internal to src/vision: the uncertainty of the track model fit (track_model_fit.hpp) beyond the
// stated u_x: a statistical part estimated from the residuals' own correlation, and the tracker's
// systematic part, which the residuals cannot show. The method, its assumptions and its accuracy
// are stated in track_analysis.hpp ("Uncertainty of the fit").
//
// Both parts are sandwich covariances of the same linearised estimator. At the solution the fit
// is weighted least squares with the Huber loss' IRLS weights w_i (1 inside the threshold), so a
// small error e of the positions moves the parameters by δ = B e with B = (AᵀWA)⁻¹AᵀW, A the
// n × 3 derivatives of the predicted x by (x0, t0, p). For errors of covariance Σ, Cov(δ) = BΣBᵀ.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace uphill::internal {

struct FitErrorInputs {
  Eigen::MatrixXd derivatives;     // A: n × 3, m per unit of x0, t0, p
  Eigen::VectorXd weights;         // w_i, the Huber loss' IRLS weights at the solution, in (0, 1]
  Eigen::VectorXd residuals;       // measured − predicted, m, in frame order
  Eigen::VectorXd x;               // measured positions, m (the bias is correlated along the path)
  Eigen::VectorXd systematic;      // the tracker's systematic error of each position, 1σ, m
  // Each frame's time error, 1σ, s, from one error shared by all frames (a measured rolling
  // shutter's readout: v_i·u(row delay)); empty: none. It moves position i by ẋ_i = −∂x/∂t0
  // times it.
  Eigen::VectorXd time_systematic;
};

struct FitErrors {
  // Statistical: Σ_ij = s²·ρ^|i−j| (AR(1) along the frames of the window), s² = Σ w r²/(Σw − 3),
  // ρ the lag-1 autocorrelation of the residuals clamped to [0, 0.98].
  Eigen::Matrix3d residual_covariance = Eigen::Matrix3d::Zero();
  double lag1 = 0;
  // Systematic: Σ_ij = σ_i σ_j exp(−|x_i − x_j|/ℓ) with the correlation length ℓ (m) unknown, so
  // the average of BΣ(ℓ)Bᵀ over ℓ ∈ {0 (independent frames), span/256 … span (×2 steps), +inf (one
  // bias)}, each equally likely: the covariance of an error whose ℓ is drawn from that prior;
  // plus the timing part below.
  Eigen::Matrix3d systematic_covariance = Eigen::Matrix3d::Zero();
  // The part of the shared time error (FitErrorInputs::time_systematic), also in
  // systematic_covariance.
  Eigen::Matrix3d timing_covariance = Eigen::Matrix3d::Zero();

  // Statistical and systematic parts together.
  Eigen::Matrix3d Covariance() const { return residual_covariance + systematic_covariance; }
};

// Requires n ≥ 4 rows and AᵀWA invertible (the caller checked the fit's rank).
FitErrors EstimateFitErrors(const FitErrorInputs& in);

}  // namespace uphill::internal
