// Every straight-line method against independent references (src/oracle: 50-digit least squares,
// York's iteration and Newton on Huber's objective in long double, Ceres' own covariance of all
// rows) on random data, and the per-row diagnostics.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>
#include <tuple>

#include <ceres/ceres.h>

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

using oracle::LineSolution;

// ---------------------------------------------------------------------------------------------
// Every method against the extended-precision oracles on random data.

TEST(IndependentCheck, OlsWlsYorkMatchTheExtendedPrecisionOracles) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const LineData d = Synthetic(40, -0.8 + static_cast<double>(seed), 3.0, seed, true);
    const LineSolution ols = oracle::OrdinaryLeastSquares(d);
    ExpectMatchesClosed(FitOrdinaryLeastSquares(d), ols, 1e-13, 1e-12);
    // OLS scaled covariance: × s².
    const FitReport fit = FitOrdinaryLeastSquares(d);
    EXPECT_TRUE(RelNear((*fit.covariance_scaled)(0, 0), ols.ScaledVarK(), 1e-12));
    EXPECT_TRUE(RelNear((*fit.covariance_scaled)(1, 1), ols.ScaledVarC(), 1e-12));
    ExpectMatchesClosed(FitWeightedLeastSquares(d), oracle::WeightedLeastSquares(d), 1e-13, 1e-12);
    ExpectMatchesClosed(FitErrorsInVariables(d), oracle::YorkLine(d), 1e-12, 1e-11);
  }
}

// York's fit hands Ceres its N residuals compressed to 3 (src/fit/internal/compressed_cost.hpp)
// and takes the covariance from ceres::Covariance of that small problem. Here Ceres sees the full
// problem instead - N residuals (Y − c − kX)/sqrt(u(Y)² + k²u(X)²) in data units, differentiated
// by Ceres' own autodiff, not the library's analytic Jacobian - and ceres::Covariance (dense
// SVD) of it at the fitted (k, c) must be the same matrix.
struct FullYorkResiduals {
  const LineData* d;
  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    for (std::size_t i = 0; i < d->size(); ++i) {
      const T variance = T(d->u_y[i] * d->u_y[i]) + theta[0] * theta[0] * (d->u_x[i] * d->u_x[i]);
      residuals[i] = (d->y[i] - theta[1] - theta[0] * d->x[i]) / sqrt(variance);
    }
    return true;
  }
};

TEST(IndependentCheck, CompressedYorkCovarianceIsCeresCovarianceOfAllRows) {
  for (const LineData& d : {PearsonYork(), Synthetic(1000, 1.3, 0.7, 5, true),
                            Synthetic(200, -0.4, 2.0, 6, true)}) {
    SCOPED_TRACE("N = " + std::to_string(d.size()));
    const FitReport fit = FitErrorsInVariables(d);
    double theta[2] = {fit.slope(), fit.intercept()};
    ceres::Problem problem;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<FullYorkResiduals, ceres::DYNAMIC, 2>(
            new FullYorkResiduals{&d}, static_cast<int>(d.size())),
        nullptr, theta);
    ceres::Covariance::Options options;
    options.algorithm_type = ceres::DENSE_SVD;
    ceres::Covariance covariance(options);
    const std::vector<std::pair<const double*, const double*>> blocks = {{theta, theta}};
    ASSERT_TRUE(covariance.Compute(blocks, &problem));
    double c[4];
    ASSERT_TRUE(covariance.GetCovarianceBlock(theta, theta, c));
    EXPECT_TRUE(RelNear(fit.covariance(0, 0), c[0], 1e-12));
    EXPECT_TRUE(RelNear(fit.covariance(0, 1), c[1], 1e-12));
    EXPECT_TRUE(RelNear(fit.covariance(1, 0), c[2], 1e-12));
    EXPECT_TRUE(RelNear(fit.covariance(1, 1), c[3], 1e-12));
    // And the fitted line is the minimum of that problem: its gradient vanishes.
    double cost = 0.0;
    std::vector<double> gradient;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient, nullptr);
    EXPECT_TRUE(RelNear(2.0 * cost, fit.chi2, 1e-12));
    // The Newton step the gradient implies, (JᵀJ)⁻¹g, against the standard errors: zero to
    // rounding (it would be ~1e-5 of σ if the fit had stopped where Ceres' cost test does).
    EXPECT_LT(std::abs(c[0] * gradient[0] + c[1] * gradient[1]), 1e-10 * std::sqrt(c[0]));
    EXPECT_LT(std::abs(c[2] * gradient[0] + c[3] * gradient[1]), 1e-10 * std::sqrt(c[3]));
  }
}

TEST(IndependentCheck, RobustIsTheWeightedFitAtItsOwnFinalWeights) {
  // The M-estimate is a fixed point of iteratively reweighted least squares: weighted least
  // squares with weights w_i/σ_i² reproduces the line and the (unscaled) covariance.
  LineData d = TwentyRowsWithOneOutlier(true);
  d.y[4] -= 0.4;  // a second, milder outlier
  for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    RobustOptions options;
    options.loss = loss;
    const FitReport robust = FitRobust(d, options);
    LineData weighted = d;
    for (std::size_t i = 0; i < d.size(); ++i)
      weighted.u_y[i] = robust.rows[i].sigma / std::sqrt(robust.rows[i].weight);
    ExpectMatchesClosed(robust, oracle::WeightedLeastSquares(weighted), 1e-10, 1e-10);
  }
}

TEST(IndependentCheck, HuberMatchesTheNewtonOracle) {
  // Truth: src/oracle's Newton iteration on Huber's objective in long double (and, without u(Y),
  // its joint fixed point with σ = 1.4826·MAD), with the IRLS covariance at the final weights.
  LineData d = Synthetic(400, 1.3, 0.7, 21, false);
  for (std::size_t i = 0; i < d.size(); i += 37) d.y[i] += 12.0 * d.u_y[i];  // gross errors
  const FitReport stated = FitRobust(d);
  const LineSolution huber = oracle::HuberLine(d);
  EXPECT_TRUE(RelNear(stated.slope(), huber.k, 1e-13));
  EXPECT_TRUE(RelNear(stated.intercept(), huber.c, 1e-13));
  EXPECT_TRUE(RelNear(stated.covariance(0, 0), huber.var_k, 1e-12));
  EXPECT_TRUE(RelNear(stated.covariance(1, 1), huber.var_c, 1e-12));
  EXPECT_TRUE(RelNear(stated.covariance(0, 1), huber.cov_kc, 1e-12));
  EXPECT_TRUE(RelNear(stated.chi2, huber.chi2, 1e-12));
  const LineData unstated{d.x, d.y, {}, {}};
  const FitReport mad = FitRobust(unstated);
  const LineSolution huber_mad = oracle::HuberLineMadScale(unstated);
  EXPECT_TRUE(RelNear(mad.slope(), huber_mad.k, 1e-12));
  EXPECT_TRUE(RelNear(mad.intercept(), huber_mad.c, 1e-12));
  EXPECT_TRUE(RelNear(mad.rows[0].sigma, huber_mad.sigma, 1e-12));
  EXPECT_TRUE(RelNear(mad.covariance(0, 0), huber_mad.var_k, 1e-11));
}

TEST(IndependentCheck, PValueAndInformationCriteria) {
  // ν = 2: P(χ²₂ ≥ x) = exp(−x/2) exactly.
  const LineData d{{0, 1, 2, 3}, {0.1, 0.9, 2.2, 2.9}, {}, {0.1, 0.2, 0.1, 0.2}};
  const FitReport wls = FitWeightedLeastSquares(d);
  ASSERT_TRUE(wls.p_value);
  EXPECT_TRUE(RelNear(*wls.p_value, std::exp(-wls.chi2 / 2.0), 1e-12));
  // AIC/BIC with stated σ: χ² + Σ ln(2πσ²) + 2p / + p ln N.
  double log_term = 0.0;
  for (double u : d.u_y) log_term += std::log(2.0 * M_PI * u * u);
  EXPECT_TRUE(RelNear(*wls.aic, wls.chi2 + log_term + 4.0, 1e-13));
  EXPECT_TRUE(RelNear(*wls.bic, wls.chi2 + log_term + 2.0 * std::log(4.0), 1e-13));
  // OLS: σ estimated, one more parameter.
  const FitReport ols = FitOrdinaryLeastSquares(d);
  const double n = 4.0;
  const double m2ll = n * (std::log(2.0 * M_PI * ols.chi2 / n) + 1.0);
  EXPECT_TRUE(RelNear(*ols.aic, m2ll + 6.0, 1e-13));
  EXPECT_TRUE(RelNear(*ols.bic, m2ll + 3.0 * std::log(n), 1e-13));
  // Comparing a stated-σ fit with an estimated-σ one is refused.
  ExpectInputError([&] { CompareModels(ols, wls); }, "fits");
}

TEST(Diagnostics, RowsOnDemandAreTheStoredRowsBitForBit) {
  // LineRowResults (line_rows.hpp) computes the rows of a fit run with keep_rows = false: they must
  // be the very numbers the fit stores with keep_rows = true, and the fit's summaries (χ², the
  // outlier and down-weighted lists) must not depend on whether rows are kept.
  LineData d = Synthetic(3000, 1.7, -0.4, 31, true);
  for (std::size_t i = 0; i < d.size(); i += 97) d.y[i] += 9.0 * d.u_y[i];  // outliers
  const LineData no_u{d.x, d.y, {}, {}};
  FitOptions stream;
  stream.keep_rows = false;
  RobustOptions robust_stream, robust_mad;
  robust_stream.fit.keep_rows = false;
  robust_mad.loss = RobustLoss::kCauchy;
  RobustOptions robust_mad_stream = robust_mad;
  robust_mad_stream.fit.keep_rows = false;
  const std::vector<std::tuple<std::string, const LineData*, FitReport, FitReport>> cases = {
      {"OLS", &d, FitOrdinaryLeastSquares(d), FitOrdinaryLeastSquares(d, stream)},
      {"WLS", &d, FitWeightedLeastSquares(d), FitWeightedLeastSquares(d, stream)},
      {"York", &d, FitErrorsInVariables(d), FitErrorsInVariables(d, stream)},
      {"Huber", &d, FitRobust(d), FitRobust(d, robust_stream)},
      {"Cauchy, estimated scale", &no_u, FitRobust(no_u, robust_mad), FitRobust(no_u, robust_mad_stream)}};
  for (const auto& [name, data, kept, streamed] : cases) {
    SCOPED_TRACE(name);
    ASSERT_EQ(kept.rows.size(), data->size());
    EXPECT_TRUE(streamed.rows.empty());
    EXPECT_EQ(streamed.chi2, kept.chi2);
    EXPECT_EQ(streamed.outliers, kept.outliers);
    EXPECT_FALSE(kept.outliers.empty());
    ASSERT_EQ(streamed.downweighted.size(), kept.downweighted.size());
    EXPECT_EQ(streamed.slope(), kept.slope());
    const LineRowResults rows(streamed, *data);
    ASSERT_EQ(rows.size(), kept.rows.size());
    std::size_t flagged = 0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const RowResult a = rows[i], &b = kept.rows[i];
      ASSERT_EQ(a.row, b.row);
      ASSERT_EQ(a.fitted, b.fitted) << i;
      ASSERT_EQ(a.residual, b.residual) << i;
      ASSERT_EQ(a.sigma, b.sigma) << i;
      ASSERT_EQ(a.normalised, b.normalised) << i;
      ASSERT_EQ(a.weight, b.weight) << i;
      ASSERT_EQ(a.outlier, b.outlier) << i;
      flagged += a.outlier;
    }
    EXPECT_EQ(flagged, kept.outliers.size());
  }
  const LineData other{{1.0, 2.0, 3.0}, {1.0, 2.5, 2.9}, {}, {}};
  EXPECT_THROW(LineRowResults(std::get<2>(cases[0]), other), std::invalid_argument);
}

TEST(Diagnostics, RowsCarryResidualsAndOutlierFlags) {
  LineData d = Synthetic(25, 1.0, 0.0, 9, false);
  d.y[7] += 8.0 * d.u_y[7];
  FitOptions options;
  options.outlier_threshold = 4.0;
  const FitReport wls = FitWeightedLeastSquares(d, options);
  ASSERT_EQ(wls.rows.size(), d.size());
  for (const RowResult& row : wls.rows) {
    EXPECT_DOUBLE_EQ(row.fitted + row.residual, d.y[row.row]);
    EXPECT_NEAR(row.fitted, wls.intercept() + wls.slope() * d.x[row.row], 1e-13);
    EXPECT_DOUBLE_EQ(row.normalised, row.residual / d.u_y[row.row]);
    EXPECT_EQ(row.outlier, std::abs(row.normalised) > 4.0);
  }
  ASSERT_EQ(wls.outliers.size(), 1u);
  EXPECT_EQ(wls.outliers[0], 7u);
  EXPECT_DOUBLE_EQ(wls.outlier_threshold, 4.0);
  EXPECT_NEAR(wls.correlation(0, 0), 1.0, 0.0);
  EXPECT_NEAR(wls.correlation(0, 1),
              wls.covariance(0, 1) / std::sqrt(wls.covariance(0, 0) * wls.covariance(1, 1)), 1e-15);
}

}  // namespace
}  // namespace uphill::testing
