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

// The prior over the tracker's correlation length ℓ, as measured: on the random ray-traced scenes
// looked at while building the tracker (uphill bench track --random; 117 scenes with the ball
// moving, 4,000 frames found within a pixel), the tracker's error along the path is 45 % (of its
// mean square) one bias shared by the scene's frames, 19 % a trend along the path (its linear and
// quadratic parts over the clip) and 36 % frame to frame (lag-1 autocorrelation 0.5). So ℓ = +inf
// has kSharedBiasShare, ℓ = 0 kIndependentShare, and the rest is spread evenly over span/256 …
// span. An even prior over all eleven (9 % each end) made the intermediate lengths, which move g
// most, 82 % of it: on those scenes the pulls' RMS of g was 0.73, on 21 fits of fresh ones 0.54.
inline constexpr double kSharedBiasShare = 0.45, kIndependentShare = 0.35;

struct FitErrors {
  // Statistical: Σ_ij = s²·ρ^|i−j| (AR(1) along the frames of the window), s² = Σ w r²/(Σw − 3),
  // ρ the lag-1 autocorrelation of the residuals clamped to [0, 0.98].
  Eigen::Matrix3d residual_covariance = Eigen::Matrix3d::Zero();
  double lag1 = 0;
  // Systematic: Σ_ij = σ_i σ_j exp(−|x_i − x_j|/ℓ) with the correlation length ℓ (m) unknown, so
  // the average of BΣ(ℓ)Bᵀ over ℓ ∈ {0 (independent frames), span/256 … span (×2 steps), +inf (one
  // bias)}, weighted by the prior below: the covariance of an error whose ℓ is drawn from it;
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
