// The uncertainty parts of the track model fit (src/vision/internal/track_fit_errors.hpp), on
// derivatives written here in closed form.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "internal/track_fit_errors.hpp"

namespace uphill::internal {
namespace {

// One error shared by every frame's time, the same for all (a pure shift), is a shift of t0 and
// nothing else: the timing part of the covariance is exactly (0, δ², 0) on its diagonal. Truth:
// the closed form (B·A = I, and the shift is A's t0 column times δ).
TEST(TrackFitErrors, ASharedTimeShiftMovesOnlyT0) {
  const int n = 40;
  const double t0 = 0.1, a = 1.5, delta = 2e-3;
  FitErrorInputs in;
  in.derivatives.resize(n, 3);
  in.weights = Eigen::VectorXd::Ones(n);
  in.residuals = Eigen::VectorXd::Zero(n);
  in.x.resize(n);
  in.systematic = Eigen::VectorXd::Zero(n);
  in.time_systematic = Eigen::VectorXd::Constant(n, delta);
  for (int i = 0; i < n; ++i) {
    const double tau = std::max(0.01 * i - t0, 0.0);  // x = x0 + a·τ²/2 after the release
    in.derivatives.row(i) << 1, -a * tau, 0.5 * tau * tau;
    in.x(i) = 0.05 + 0.5 * a * tau * tau;
  }
  const FitErrors e = EstimateFitErrors(in);
  EXPECT_NEAR(std::sqrt(e.timing_covariance(1, 1)), delta, 1e-12);
  EXPECT_NEAR(e.timing_covariance(0, 0), 0, 1e-20);
  EXPECT_NEAR(e.timing_covariance(2, 2), 0, 1e-20);
  EXPECT_NEAR(std::sqrt(e.systematic_covariance(1, 1)), delta, 1e-12);  // the tracker's part is 0 here
}

// The systematic part is the covariance of a tracker bias whose correlation length ℓ is drawn
// from the stated prior (0, span/256 … span, +inf, weighted as below). Truth: a Monte Carlo of
// that process, written here: draw ℓ, draw the bias from its Gaussian process, move the parameters
// by the weighted least-squares response (unit weights: B = (AᵀA)⁻¹Aᵀ), and take the sample
// covariance. 20000 draws: the sample variances are within a few per cent of the stated ones.
TEST(TrackFitErrors, SystematicPartIsTheCovarianceOfABiasOfUnknownCorrelationLength) {
  const int n = 30;
  const double a = 1.5, sigma0 = 0.02e-3, sigma_speed = 0.3e-3;
  FitErrorInputs in;
  in.derivatives.resize(n, 3);
  in.weights = Eigen::VectorXd::Ones(n);
  in.residuals = Eigen::VectorXd::Zero(n);
  in.x.resize(n);
  in.systematic.resize(n);
  for (int i = 0; i < n; ++i) {
    const double tau = 0.01 * (i + 1);  // released at t0 = 0: x = x0 + a·τ²/2, every x distinct
    in.derivatives.row(i) << 1, -a * tau, 0.5 * tau * tau;
    in.x(i) = 0.05 + 0.5 * a * tau * tau;
    in.systematic(i) = sigma0 + sigma_speed * a * tau;  // grows with the speed, as the tracker's
  }
  const FitErrors e = EstimateFitErrors(in);

  const Eigen::MatrixXd& d = in.derivatives;
  const Eigen::MatrixXd b = (d.transpose() * d).ldlt().solve(d.transpose());
  const double span = in.x.maxCoeff() - in.x.minCoeff();
  std::vector<Eigen::MatrixXd> factors;  // L with LLᵀ = Σ(ℓ), one per ℓ of the prior
  for (int k = -1; k <= 9; ++k) {
    const double length = k < 0 ? 0.0 : k == 9 ? std::numeric_limits<double>::infinity() : span * std::ldexp(1.0, k - 8);
    Eigen::MatrixXd cov(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        cov(i, j) = in.systematic(i) * in.systematic(j) *
                    (i == j ? 1.0 : length == 0 ? 0.0 : std::exp(-std::abs(in.x(i) - in.x(j)) / length));
    cov.diagonal() *= 1 + 1e-12;  // ℓ = +inf is rank one
    factors.push_back(cov.llt().matrixL());
  }
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  // The prior as track_fit_errors.hpp states it: ℓ = 0 with 0.35, +inf with 0.45, the nine lengths
  // between with 0.20 / 9 each.
  std::vector<double> prior(factors.size(), 0.20 / 9);
  prior.front() = 0.35, prior.back() = 0.45;
  std::discrete_distribution<int> pick(prior.begin(), prior.end());
  const int draws = 20000;
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  Eigen::VectorXd z(n);
  for (int r = 0; r < draws; ++r) {
    for (int i = 0; i < n; ++i) z(i) = normal(random);
    const Eigen::Vector3d delta = b * (factors[pick(random)] * z);
    sample += delta * delta.transpose() / draws;
  }
  for (int j = 0; j < 3; ++j)
    EXPECT_NEAR(sample(j, j), e.systematic_covariance(j, j), 0.06 * e.systematic_covariance(j, j)) << j;
}

}  // namespace
}  // namespace uphill::internal
