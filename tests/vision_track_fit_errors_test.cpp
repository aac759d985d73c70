// The uncertainty parts of the track model fit (src/vision/internal/track_fit_errors.hpp), on
// derivatives written here in closed form.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

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
  EXPECT_NEAR(std::sqrt(e.systematic_variance(1)), delta, 1e-12);  // the tracker's part is 0 here
}

}  // namespace
}  // namespace uphill::internal
