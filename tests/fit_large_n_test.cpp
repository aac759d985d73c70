// The straight-line fits on 10^6 rows: no N-sized matrix, and the synthetic truth within 5 sigma.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fit/least_squares_line.hpp"
#include "fit/line_rows.hpp"
#include "fit/model_comparison.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"
#include "oracle/line_references.hpp"
#include "fit_test_support.hpp"

#ifndef UPHILL_FIT_LARGE_N
#define UPHILL_FIT_LARGE_N 1000000
#endif

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// 10^6 rows (10^5 under the sanitizers): the fits hold no N-sized matrix and land within 5σ of the
// truth of the synthetic data (their speed is measured by `uphill bench fit`, not here).

void ExpectWithinFiveSigma(const FitReport& fit, std::size_t n, double k, double c) {
  ASSERT_EQ(fit.n, n);
  const auto cov = fit.PrimaryCovariance();
  ASSERT_TRUE(cov);
  EXPECT_LT(std::abs(fit.slope() - k), 5.0 * std::sqrt((*cov)(0, 0)));
  EXPECT_LT(std::abs(fit.intercept() - c), 5.0 * std::sqrt((*cov)(1, 1)));
  EXPECT_TRUE(fit.solver.converged) << fit.solver.termination;
}

constexpr std::size_t kLargeN = UPHILL_FIT_LARGE_N;

TEST(LargeN, OlsOnAMillionRows) {
  const LineData d = Synthetic(kLargeN, 1.3, 0.7, 11, false);
  ExpectWithinFiveSigma(FitOrdinaryLeastSquares(d), kLargeN, 1.3, 0.7);
}

TEST(LargeN, WlsOnAMillionRows) {
  const LineData d = Synthetic(kLargeN, 1.3, 0.7, 11, false);
  const FitReport wls = FitWeightedLeastSquares(d);
  ExpectWithinFiveSigma(wls, kLargeN, 1.3, 0.7);
  // With the right u's, χ²/ν ≈ 1 within a few sqrt(2/ν).
  EXPECT_NEAR(*wls.reduced_chi2, 1.0, 5.0 * std::sqrt(2.0 / static_cast<double>(kLargeN)));
}

TEST(LargeN, YorkOnAMillionRows) {
  const LineData d = Synthetic(kLargeN, 1.3, 0.7, 12, true);
  const FitReport york = FitErrorsInVariables(d);
  ExpectWithinFiveSigma(york, kLargeN, 1.3, 0.7);
  EXPECT_NEAR(*york.reduced_chi2, 1.0, 5.0 * std::sqrt(2.0 / static_cast<double>(kLargeN)));
}

TEST(LargeN, RobustOnAMillionRows) {
  const std::size_t n = kLargeN;
  LineData d = Synthetic(n, 1.3, 0.7, 13, false);
  for (std::size_t i = 0; i < n; i += 100) d.y[i] += 40.0 * d.u_y[i];  // 1 % gross errors
  const FitReport robust = FitRobust(d);
  EXPECT_LT(std::abs(robust.slope() - 1.3), 5.0 * robust.Parameter("k").se_unscaled);
  EXPECT_GE(robust.downweighted.size(), n / 100);
}

}  // namespace
}  // namespace uphill::testing
