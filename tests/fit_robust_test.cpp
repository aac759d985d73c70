// The robust (Huber) line fit: a gross outlier named and down-weighted, least squares without
// outliers, Ceres alone from a cold start agreeing (truth: the weighted fit and the data's design).
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

namespace uphill::testing {
namespace {

TEST(Robust, NamesAndDownWeightsAGrossOutlier) {
  for (const bool with_u : {true, false}) {
    for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
      SCOPED_TRACE(std::string(with_u ? "u(Y) given, " : "robust scale, ") +
                   (loss == RobustLoss::kHuber ? "Huber" : "Cauchy"));
      const LineData d = TwentyRowsWithOneOutlier(with_u);
      RobustOptions options;
      options.loss = loss;
      const FitReport robust = FitRobust(d, options);
      const FitReport ols = FitOrdinaryLeastSquares(d);
      // Row 13 is named, with a small weight, and flagged as an outlier.
      bool named = false;
      for (const DownWeightedRow& row : robust.downweighted) {
        if (row.row != 13) continue;
        named = true;
        EXPECT_LT(row.weight, 0.05);
        EXPECT_GT(row.normalised, 20.0);
      }
      EXPECT_TRUE(named);
      EXPECT_EQ(robust.rows[13].weight, [&] {
        for (const DownWeightedRow& row : robust.downweighted)
          if (row.row == 13) return row.weight;
        return -1.0;
      }());
      ASSERT_FALSE(robust.outliers.empty());
      EXPECT_EQ(robust.outliers.front(), 13u);
      // No other row is an outlier, and few others are touched at all.
      EXPECT_EQ(robust.outliers.size(), 1u);
      EXPECT_LE(robust.downweighted.size(), 6u);
      // The slope stays near the truth (0.5; σ(k) ≈ 0.0077), where OLS is dragged.
      EXPECT_NEAR(robust.slope(), 0.5, 0.025);
      EXPECT_LT(std::abs(robust.slope() - 0.5), std::abs(ols.slope() - 0.5));
      EXPECT_FALSE(robust.aic);
      EXPECT_FALSE(robust.p_value);
    }
  }
}

TEST(Robust, WithoutOutliersHuberIsLeastSquares) {
  // Every |r/σ| below the Huber scale: the loss is quadratic everywhere, so the fit is WLS.
  LineData d = Synthetic(30, 2.0, 1.0, 5, false);
  for (double& u : d.u_y) u *= 10.0;  // residuals ≪ σ
  const FitReport robust = FitRobust(d);
  const FitReport wls = FitWeightedLeastSquares(d);
  EXPECT_TRUE(robust.downweighted.empty());
  EXPECT_TRUE(RelNear(robust.slope(), wls.slope(), 1e-13));
  EXPECT_TRUE(RelNear(robust.covariance(0, 0), wls.covariance(0, 0), 1e-12));
}

TEST(Robust, CeresAloneFromColdStartAgrees) {
  for (const bool with_u : {true, false}) {
    for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
      SCOPED_TRACE(std::string(with_u ? "u(Y) given, " : "robust scale, ") +
                   (loss == RobustLoss::kHuber ? "Huber" : "Cauchy"));
      RobustOptions seeded, cold;
      seeded.loss = cold.loss = loss;
      cold.fit.seed_with_closed_form = false;
      const LineData d = TwentyRowsWithOneOutlier(with_u);
      const FitReport a = FitRobust(d, seeded), b = FitRobust(d, cold);
      EXPECT_FALSE(b.solver.seeded_with_closed_form);
      EXPECT_TRUE(RelNear(b.slope(), a.slope(), 1e-12));
      EXPECT_TRUE(RelNear(b.intercept(), a.intercept(), 1e-12));
      EXPECT_TRUE(RelNear(b.covariance(0, 0), a.covariance(0, 0), 1e-10));
    }
  }
}

}  // namespace
}  // namespace uphill::testing
