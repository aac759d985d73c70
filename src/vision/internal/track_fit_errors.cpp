#include "track_fit_errors.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace uphill::internal {

FitErrors EstimateFitErrors(const FitErrorInputs& in) {
  const Eigen::Index n = in.residuals.size();
  FitErrors out;
  // B = (AᵀWA)⁻¹AᵀW (3 × n): the parameters' response to a small error of each position.
  const Eigen::MatrixXd wa = in.weights.asDiagonal() * in.derivatives;
  const Eigen::MatrixXd b = (in.derivatives.transpose() * wa).ldlt().solve(wa.transpose());

  // Statistical part: AR(1) of the residuals in frame order.
  double ss = 0, lagged = 0, weight_sum = in.weights.sum();
  for (Eigen::Index i = 0; i < n; ++i) {
    ss += in.residuals(i) * in.residuals(i);
    if (i + 1 < n) lagged += in.residuals(i) * in.residuals(i + 1);
  }
  out.lag1 = ss > 0 ? std::clamp(lagged / ss, 0.0, 0.98) : 0.0;
  double weighted_ss = 0;
  for (Eigen::Index i = 0; i < n; ++i) weighted_ss += in.weights(i) * in.residuals(i) * in.residuals(i);
  const double s2 = weighted_ss / std::max(weight_sum - 3.0, 1.0);
  Eigen::MatrixXd sigma(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) sigma(i, j) = s2 * std::pow(out.lag1, static_cast<double>(std::abs(i - j)));
  out.residual_covariance = b * sigma * b.transpose();

  // The shared time error: one error, so a rank-one covariance (B e)(B e)ᵀ.
  if (in.time_systematic.size() == n) {
    const Eigen::Vector3d moved = b * in.derivatives.col(1).cwiseProduct(in.time_systematic);
    out.timing_covariance = moved * moved.transpose();
  }

  // Systematic part: the average over the correlation lengths (the header says why).
  const double span = in.x.maxCoeff() - in.x.minCoeff();
  std::vector<double> lengths = {0.0};
  for (int k = 8; k >= 0 && span > 0; --k) lengths.push_back(span * std::ldexp(1.0, -k));
  lengths.push_back(std::numeric_limits<double>::infinity());
  const double trend_share =
      (1.0 - kSharedBiasShare - kIndependentShare) / static_cast<double>(std::max<std::size_t>(lengths.size() - 2, 1));
  double shares = 0;
  for (double length : lengths) {
    const double share = length == 0 ? kIndependentShare : std::isinf(length) ? kSharedBiasShare : trend_share;
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < n; ++j) {
        const double d = std::abs(in.x(i) - in.x(j));
        const double rho = i == j ? 1.0 : length == 0 ? 0.0 : std::isinf(length) ? 1.0 : std::exp(-d / length);
        sigma(i, j) = in.systematic(i) * in.systematic(j) * rho;
      }
    out.systematic_covariance += share * (b * sigma * b.transpose());
    shares += share;
  }
  out.systematic_covariance /= shares;  // 1 but where all frames lie at one x
  out.systematic_covariance += out.timing_covariance;
  return out;
}

}  // namespace uphill::internal
