// The straight-line fits (src/fit) against certified and published values: NIST StRD Norris
// (certified to 15 digits), Pearson's data with York's weights (York 1966 / Williamson 1968, the
// published solution), and the numerical care X ≈ 1e9 needs (truth: src/oracle's 50-digit solution).
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

using oracle::LineSolution;

// ---------------------------------------------------------------------------------------------
// NIST StRD "Norris": certified values to ≥ 12 significant digits (we see ~14).

constexpr double kNorrisB0 = -0.262323073774029;
constexpr double kNorrisB1 = 1.00211681802045;
constexpr double kNorrisSdB0 = 0.232818234301152;
constexpr double kNorrisSdB1 = 0.429796848199937E-03;
constexpr double kNorrisResidualSd = 0.884796396144373;
constexpr double kNorrisRSquared = 0.999993745883712;
constexpr double kNorrisSsr = 26.6173985294224;

void ExpectNorrisCertified(const FitReport& fit) {
  ASSERT_EQ(fit.n, 36u);
  EXPECT_EQ(fit.dof, 34);
  EXPECT_TRUE(RelNear(fit.intercept(), kNorrisB0, 1e-12));
  EXPECT_TRUE(RelNear(fit.slope(), kNorrisB1, 1e-13));
  ASSERT_TRUE(fit.StandardError("c", ErrorScaling::kScaled));
  EXPECT_TRUE(RelNear(*fit.StandardError("c", ErrorScaling::kScaled), kNorrisSdB0, 1e-12));
  EXPECT_TRUE(RelNear(*fit.StandardError("k", ErrorScaling::kScaled), kNorrisSdB1, 1e-12));
  ASSERT_TRUE(fit.reduced_chi2);
  EXPECT_TRUE(RelNear(std::sqrt(*fit.reduced_chi2), kNorrisResidualSd, 1e-12));
  EXPECT_TRUE(RelNear(fit.chi2, kNorrisSsr, 1e-12));
  ASSERT_TRUE(fit.r_squared);
  EXPECT_TRUE(RelNear(*fit.r_squared, kNorrisRSquared, 1e-14));
}

TEST(NistNorris, DataFileHas36Rows) {
  const LineData d = Norris();
  EXPECT_EQ(d.x.size(), 36u);
  EXPECT_EQ(d.y.size(), 36u);
  EXPECT_EQ(d.x.front(), 0.2);
  EXPECT_EQ(d.y.front(), 0.1);
  EXPECT_EQ(d.x.back(), 0.5);
  EXPECT_EQ(d.y.back(), 0.2);
}

TEST(NistNorris, OlsReproducesCertifiedValues) {
  const FitReport fit = FitOrdinaryLeastSquares(Norris());
  ExpectNorrisCertified(fit);
  EXPECT_EQ(fit.primary_scaling, ErrorScaling::kScaled);
  EXPECT_FALSE(fit.p_value);  // no stated uncertainties to test against
  EXPECT_TRUE(fit.solver.converged) << fit.solver.termination;
  EXPECT_TRUE(fit.solver.seeded_with_closed_form);
}

TEST(NistNorris, CeresAloneFromColdStartReproducesCertifiedValues) {
  FitOptions options;
  options.seed_with_closed_form = false;
  const FitReport fit = FitOrdinaryLeastSquares(Norris(), options);
  ExpectNorrisCertified(fit);
  EXPECT_FALSE(fit.solver.seeded_with_closed_form);
  EXPECT_GE(fit.solver.iterations, 1);
}

TEST(NistNorris, UnitWeightWlsGivesTheUnscaledCovariance) {
  // GSL's fit/test.c lists (XᵀX)⁻¹ for unit weights, "computed from octave", in (c, k) order:
  // 6.92384428759429e-02, -9.89095016390515e-05, 2.35960747164148e-07.
  LineData d = Norris();
  d.u_y.assign(d.size(), 1.0);
  const FitReport wls = FitWeightedLeastSquares(d);
  const FitReport ols = FitOrdinaryLeastSquares(d);
  EXPECT_TRUE(RelNear(wls.slope(), kNorrisB1, 1e-13));
  EXPECT_TRUE(RelNear(wls.intercept(), kNorrisB0, 1e-12));
  EXPECT_TRUE(RelNear(wls.covariance(1, 1), 6.92384428759429e-02, 1e-12));
  EXPECT_TRUE(RelNear(wls.covariance(0, 1), -9.89095016390515e-05, 1e-12));
  EXPECT_TRUE(RelNear(wls.covariance(0, 0), 2.35960747164148e-07, 1e-12));
  EXPECT_TRUE(RelNear(ols.covariance(0, 0), wls.covariance(0, 0), 1e-13));
  EXPECT_TRUE(RelNear(wls.chi2, kNorrisSsr, 1e-12));
  EXPECT_TRUE(wls.p_value);
  EXPECT_EQ(wls.primary_scaling, ErrorScaling::kUnscaled);
  EXPECT_FALSE(ols.notes.empty());  // "OLS ignores the given uncertainties"
}

TEST(NistNorris, YorkWithNegligibleXErrorsIsWls) {
  LineData d = Norris();
  d.u_y.assign(d.size(), 1.0);
  d.u_x.assign(d.size(), 0.0);
  const FitReport york = FitErrorsInVariables(d);
  EXPECT_TRUE(RelNear(york.slope(), kNorrisB1, 1e-13));
  EXPECT_TRUE(RelNear(york.intercept(), kNorrisB0, 1e-12));
  EXPECT_TRUE(RelNear(york.covariance(0, 0), 2.35960747164148e-07, 1e-12));
  ASSERT_FALSE(york.notes.empty());
}

// ---------------------------------------------------------------------------------------------
// Pearson's data with York's weights.

TEST(PearsonYork, ReproducesPublishedSolution) {
  const FitReport fit = FitErrorsInVariables(PearsonYork());
  ASSERT_EQ(fit.n, 10u);
  // bfsl's tests (9–10 digits) and Williamson's values as tabulated by kmpfit (12 digits).
  EXPECT_NEAR(fit.slope(), -0.480533407, 5e-10);
  EXPECT_NEAR(fit.intercept(), 5.479910224, 5e-10);
  EXPECT_NEAR(fit.slope(), -0.48053340745, 5e-12);
  EXPECT_NEAR(fit.intercept(), 5.47991022403, 5e-12);
  // York's (unscaled) standard errors and the MSWD.
  EXPECT_NEAR(fit.Parameter("k").se_unscaled, 0.0579850090, 5e-11);
  EXPECT_NEAR(fit.Parameter("c").se_unscaled, 0.294970735, 5e-10);
  ASSERT_TRUE(fit.reduced_chi2);
  EXPECT_NEAR(*fit.reduced_chi2, 1.483294149, 5e-10);
  EXPECT_EQ(fit.dof, 8);
  // Scaled ("external") errors: × sqrt(MSWD).
  ASSERT_TRUE(fit.Parameter("k").se_scaled);
  EXPECT_NEAR(*fit.Parameter("k").se_scaled, 0.07062, 5e-6);
  EXPECT_NEAR(*fit.Parameter("c").se_scaled, 0.35925, 5e-6);
  EXPECT_LT(fit.correlation(0, 1), 0.0);
  EXPECT_NEAR(fit.chi2, 8 * 1.483294149, 5e-9);
  // ν = 8 is even: P(χ²₈ ≥ x) = e^(−x/2)·Σ_{j<4} (x/2)^j/j!, independent of Boost.
  ASSERT_TRUE(fit.p_value);
  const double h = fit.chi2 / 2.0;
  EXPECT_TRUE(RelNear(*fit.p_value, std::exp(-h) * (1 + h + h * h / 2 + h * h * h / 6), 1e-12));
  EXPECT_TRUE(fit.solver.converged) << fit.solver.termination;
}

TEST(PearsonYork, CeresAloneFromColdStartFindsTheSameLine) {
  FitOptions options;
  options.seed_with_closed_form = false;
  const FitReport cold = FitErrorsInVariables(PearsonYork(), options);
  const FitReport seeded = FitErrorsInVariables(PearsonYork());
  EXPECT_TRUE(RelNear(cold.slope(), seeded.slope(), 1e-13));
  EXPECT_TRUE(RelNear(cold.intercept(), seeded.intercept(), 1e-13));
  EXPECT_TRUE(RelNear(cold.covariance(0, 0), seeded.covariance(0, 0), 1e-12));
}

TEST(PearsonYork, MatchesYorksIterationAndErrorFormulas) {
  const LineData d = PearsonYork();
  ExpectMatchesClosed(FitErrorsInVariables(d), oracle::YorkLine(d), 1e-13, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Numerical care: X ≈ 1e9 with a spread of 1 against the same data shifted to 0.

TEST(NumericalCare, XNearOneBillionLosesNoDigits) {
  const double shift = 1e9;
  LineData small, big;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i <= 64; ++i) {
    const double t = i / 64.0;  // exact, and so is 1e9 + t (ulp(1e9) = 2^-23)
    small.x.push_back(t);
    big.x.push_back(shift + t);
    ASSERT_EQ(big.x.back() - shift, t);
    const double y = 0.25 + 1.5 * t + noise(rng);
    small.y.push_back(y);
    big.y.push_back(y);
    small.u_y.push_back(0.01 * (1 + i % 3));
    small.u_x.push_back(0.002 * (1 + i % 2));
  }
  big.u_y = small.u_y;
  big.u_x = small.u_x;
  const auto check = [&](const FitReport& s, const FitReport& b, const char* what) {
    SCOPED_TRACE(what);
    EXPECT_TRUE(RelNear(b.slope(), s.slope(), 1e-12));
    EXPECT_TRUE(RelNear(b.intercept(), s.intercept() - s.slope() * shift, 1e-12));
    EXPECT_TRUE(RelNear(b.Parameter("k").se_unscaled, s.Parameter("k").se_unscaled, 1e-12));
    // var(c) at X = 1e9 from the small fit's covariance.
    const double var_c =
        s.covariance(1, 1) - 2.0 * shift * s.covariance(0, 1) + shift * shift * s.covariance(0, 0);
    EXPECT_TRUE(RelNear(b.covariance(1, 1), var_c, 1e-10));
    EXPECT_TRUE(RelNear(b.chi2, s.chi2, 1e-10));
  };
  check(FitOrdinaryLeastSquares(small), FitOrdinaryLeastSquares(big), "OLS");
  check(FitWeightedLeastSquares(small), FitWeightedLeastSquares(big), "WLS");
  check(FitErrorsInVariables(small), FitErrorsInVariables(big), "York");
  check(FitRobust({small.x, small.y, {}, small.u_y}), FitRobust({big.x, big.y, {}, big.u_y}),
        "robust");
}

}  // namespace
}  // namespace uphill::testing
