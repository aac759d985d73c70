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
  // Systematic, per parameter: the largest variance over the correlation lengths ℓ (m) of
  // Σ_ij = σ_i σ_j exp(−|x_i − x_j|/ℓ), ℓ from independent frames (0) to one bias (+inf).
  Eigen::Vector3d systematic_variance = Eigen::Vector3d::Zero();
  Eigen::Vector3d systematic_length = Eigen::Vector3d::Zero();  // the ℓ of that maximum, m
  std::vector<Eigen::Matrix3d> systematic_covariances;         // one per ℓ tried, timing included
  // The part of the shared time error (FitErrorInputs::time_systematic), in every ℓ's covariance.
  Eigen::Matrix3d timing_covariance = Eigen::Matrix3d::Zero();

  // The largest variance of a linear combination gᵀδ over the ℓ tried, statistical part included.
  double WorstVariance(const Eigen::Vector3d& g) const;
};

// Requires n ≥ 4 rows and AᵀWA invertible (the caller checked the fit's rank).
FitErrors EstimateFitErrors(const FitErrorInputs& in);

}  // namespace uphill::internal
