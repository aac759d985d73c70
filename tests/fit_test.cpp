// The straight-line fits (src/fit): certified and published reference values, numerical care
// (X ≈ 1e9), the hard cases, 10^6 rows, the robust fit, and an independent long-double closed
// form for every method's parameters and covariance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <ceres/ceres.h>

#include "fit/least_squares_line.hpp"
#include "fit/line_rows.hpp"
#include "fit/model_comparison.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"
#include "oracle/line_references.hpp"

#ifndef UPHILL_FIT_LARGE_N
#define UPHILL_FIT_LARGE_N 1000000
#endif

namespace uphill::testing {
namespace {

// ---------------------------------------------------------------------------------------------
// Helpers

// Whitespace-separated numeric columns; lines starting with '#' are comments.
std::vector<std::vector<double>> ReadColumns(const std::string& file, std::size_t columns) {
  std::ifstream in(std::string(UPHILL_TEST_DATA_DIR) + "/" + file);
  EXPECT_TRUE(in.good()) << "cannot open " << file;
  std::vector<std::vector<double>> out(columns);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    for (std::size_t c = 0; c < columns; ++c) {
      double v = 0.0;
      fields >> v;
      EXPECT_FALSE(fields.fail()) << file << ": bad line '" << line << "'";
      out[c].push_back(v);
    }
  }
  return out;
}

// |actual − expected| ≤ rel·|expected|, i.e. agreement to about −log10(rel) significant digits.
::testing::AssertionResult RelNear(double actual, double expected, double rel) {
  const double err = std::abs(actual - expected);
  if (err <= rel * std::abs(expected)) return ::testing::AssertionSuccess();
  std::ostringstream msg;
  msg.precision(17);
  msg << "actual " << actual << ", expected " << expected << ", relative error "
      << err / std::abs(expected) << " > " << rel;
  return ::testing::AssertionFailure() << msg.str();
}

LineData Norris() {
  const auto cols = ReadColumns("nist_norris.dat", 2);  // y x
  LineData d;
  d.y = cols[0];
  d.x = cols[1];
  return d;
}

LineData PearsonYork() {
  const auto cols = ReadColumns("pearson_york.dat", 4);  // x w_x y w_y
  LineData d;
  d.x = cols[0];
  d.y = cols[2];
  for (double w : cols[1]) d.u_x.push_back(1.0 / std::sqrt(w));
  for (double w : cols[3]) d.u_y.push_back(1.0 / std::sqrt(w));
  return d;
}

// Y = c + k·X + noise with per-row u(Y) (and u(X) when errors_in_x: X observed with noise).
LineData Synthetic(std::size_t n, double k, double c, std::uint64_t seed, bool errors_in_x) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 10.0);
  std::uniform_real_distribution<double> spread(0.5, 2.0);
  std::normal_distribution<double> normal;
  LineData d;
  d.x.resize(n);
  d.y.resize(n);
  d.u_y.resize(n);
  if (errors_in_x) d.u_x.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x_true = uniform(rng);
    d.u_y[i] = 0.05 * spread(rng);
    d.y[i] = c + k * x_true + d.u_y[i] * normal(rng);
    if (errors_in_x) {
      d.u_x[i] = 0.03 * spread(rng);
      d.x[i] = x_true + d.u_x[i] * normal(rng);
    } else {
      d.x[i] = x_true;
    }
  }
  return d;
}

template <typename F>
void ExpectInputError(F&& f, const std::string& quantity) {
  try {
    f();
    ADD_FAILURE() << "no InputError (expected one about " << quantity << ")";
  } catch (const InputError& e) {
    EXPECT_EQ(e.quantity(), quantity) << e.what();
    EXPECT_FALSE(e.rule().empty());
  }
}

// ---------------------------------------------------------------------------------------------
// Independent references: src/oracle (50-digit least squares, York's iteration in long double),
// written without the fit layer's code.

using oracle::LineSolution;

void ExpectMatchesClosed(const FitReport& fit, const LineSolution& closed, double rel_values,
                         double rel_covariance) {
  EXPECT_TRUE(RelNear(fit.slope(), static_cast<double>(closed.k), rel_values));
  EXPECT_TRUE(RelNear(fit.intercept(), static_cast<double>(closed.c), rel_values));
  EXPECT_TRUE(RelNear(fit.covariance(0, 0), static_cast<double>(closed.var_k), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(1, 1), static_cast<double>(closed.var_c), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(0, 1), static_cast<double>(closed.cov_kc), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(1, 0), static_cast<double>(closed.cov_kc), rel_covariance));
  EXPECT_TRUE(RelNear(fit.chi2, static_cast<double>(closed.chi2), 1e-10));
}

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

// ---------------------------------------------------------------------------------------------
// Hard cases.

TEST(HardCases, TooFewRowsAreRefused) {
  ExpectInputError([] { FitOrdinaryLeastSquares({}); }, "rows");
  ExpectInputError([] { FitOrdinaryLeastSquares({{1.0}, {2.0}, {}, {}}); }, "rows");
  ExpectInputError([] { FitWeightedLeastSquares({{1.0}, {2.0}, {}, {0.1}}); }, "rows");
  ExpectInputError([] { FitErrorsInVariables({{1.0}, {2.0}, {0.1}, {0.1}}); }, "rows");
  ExpectInputError([] { FitRobust({{1.0}, {2.0}, {}, {}}); }, "rows");
}

TEST(HardCases, AllXEqualIsRefused) {
  const LineData d{{3.0, 3.0, 3.0}, {1.0, 2.0, 3.0}, {0.1, 0.1, 0.1}, {0.1, 0.1, 0.1}};
  ExpectInputError([&] { FitOrdinaryLeastSquares(d); }, "X");
  ExpectInputError([&] { FitWeightedLeastSquares(d); }, "X");
  ExpectInputError([&] { FitErrorsInVariables(d); }, "X");
  ExpectInputError([&] { FitRobust({d}); }, "X");
}

TEST(HardCases, NonFiniteValuesAreRefused) {
  const double nan = std::nan("");
  const double inf = INFINITY;
  ExpectInputError([&] { FitOrdinaryLeastSquares({{1, 2, nan}, {1, 2, 3}, {}, {}}); }, "X[2]");
  ExpectInputError([&] { FitOrdinaryLeastSquares({{1, 2, 3}, {1, inf, 3}, {}, {}}); }, "Y[1]");
  ExpectInputError(
      [&] {
        FitWeightedLeastSquares({{1, 2, 3}, {1, 2, 3}, {}, {0.1, nan, 0.1}});
      },
      "u(Y)[1]");
  ExpectInputError(
      [&] {
        FitErrorsInVariables({{1, 2, 3}, {1, 2, 3}, {0.1, 0.1, inf}, {1, 1, 1}});
      },
      "u(X)[2]");
}

TEST(HardCases, ZeroOrMissingUncertaintiesAreRefusedWhereNeeded) {
  const std::vector<double> x{1, 2, 3}, y{2, 4, 7};
  ExpectInputError([&] { FitWeightedLeastSquares({x, y, {}, {}}); }, "u(Y)");
  ExpectInputError([&] { FitWeightedLeastSquares({x, y, {}, {0.1, 0.0, 0.1}}); }, "u(Y)[1]");
  ExpectInputError([&] { FitWeightedLeastSquares({x, y, {}, {0.1, -1.0, 0.1}}); }, "u(Y)[1]");
  ExpectInputError([&] { FitWeightedLeastSquares({x, y, {}, {0.1, 0.1}}); }, "u(Y)");
  ExpectInputError([&] { FitErrorsInVariables({x, y, {}, {0.1, 0.1, 0.1}}); }, "u(X)");
  ExpectInputError([&] { FitErrorsInVariables({x, y, {0.1, 0.1, 0.1}, {}}); }, "u(Y)");
  ExpectInputError(
      [&] {
        FitErrorsInVariables({x, y, {0.1, 0.1, 0.1}, {0.1, 0.0, 0.1}});
      },
      "u(Y)[1]");
  ExpectInputError(
      [&] {
        FitErrorsInVariables({x, y, {0.1, -0.1, 0.1}, {0.1, 0.1, 0.1}});
      },
      "u(X)[1]");
  ExpectInputError([&] { FitRobust({x, y, {}, {0.1, 0.0, 0.1}}); }, "u(Y)[1]");
  // u(X) = 0 is an exactly known X, allowed for York; OLS and the robust fit without u are fine.
  EXPECT_NO_THROW(FitErrorsInVariables({x, y, {0.0, 0.1, 0.0}, {0.1, 0.1, 0.1}}));
  EXPECT_NO_THROW(FitOrdinaryLeastSquares({x, y, {}, {}}));
  EXPECT_NO_THROW(FitRobust({x, y, {}, {}}));
  // Columns of different lengths.
  ExpectInputError([&] { FitOrdinaryLeastSquares({x, {1, 2}, {}, {}}); }, "Y");
}

TEST(HardCases, TwoRowsAreAnExactFitAndSayWhatCannotBeEstimated) {
  const LineData d{{1.0, 3.0}, {2.0, 6.0}, {0.1, 0.2}, {0.3, 0.4}};
  for (const FitReport& fit : {FitOrdinaryLeastSquares(d), FitWeightedLeastSquares(d),
                               FitErrorsInVariables(d), FitRobust({d})}) {
    SCOPED_TRACE(MethodName(fit.method));
    EXPECT_TRUE(fit.exact);
    EXPECT_EQ(fit.dof, 0);
    EXPECT_NEAR(fit.slope(), 2.0, 1e-15);
    EXPECT_NEAR(fit.intercept(), 0.0, 1e-14);
    EXPECT_FALSE(fit.reduced_chi2);
    EXPECT_FALSE(fit.p_value);
    EXPECT_FALSE(fit.covariance_scaled);
    EXPECT_FALSE(fit.Parameter("k").se_scaled);
    EXPECT_NEAR(fit.chi2, 0.0, 1e-25);
    bool noted = false;
    for (const std::string& note : fit.notes) noted |= note.find("exact fit") != std::string::npos;
    EXPECT_TRUE(noted);
    for (const RowResult& row : fit.rows) EXPECT_FALSE(row.outlier);
  }
  // OLS: nothing to report as "the" covariance. WLS: the stated u(Y) propagated,
  // var(k) = (u1² + u2²)/(x2 − x1)².
  EXPECT_FALSE(FitOrdinaryLeastSquares(d).PrimaryCovariance());
  const FitReport wls = FitWeightedLeastSquares(d);
  ASSERT_TRUE(wls.PrimaryCovariance());
  EXPECT_TRUE(RelNear(wls.covariance(0, 0), (0.09 + 0.16) / 4.0, 1e-14));
  // York: var(k) = (u(Y1)² + k²u(X1)² + u(Y2)² + k²u(X2)²)/(x2 − x1)² for two rows.
  const FitReport york = FitErrorsInVariables(d);
  EXPECT_TRUE(RelNear(york.covariance(0, 0), (0.09 + 4 * 0.01 + 0.16 + 4 * 0.04) / 4.0, 1e-13));
}

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

// ---------------------------------------------------------------------------------------------
// Robust fit: one gross outlier among 20 rows.

LineData TwentyRowsWithOneOutlier(bool with_u) {
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> noise(0.0, 0.1);
  LineData d;
  for (int i = 0; i < 20; ++i) {
    d.x.push_back(i * 0.5);
    d.y.push_back(2.0 + 0.5 * d.x.back() + noise(rng));
    if (with_u) d.u_y.push_back(0.1);
  }
  d.y[13] += 5.0;  // 50 σ
  return d;
}

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

TEST(HardCases, InvalidOptionsAreRefused) {
  const LineData d = TwentyRowsWithOneOutlier(true);
  FitOptions bad;
  bad.outlier_threshold = -1.0;
  ExpectInputError([&] { FitWeightedLeastSquares(d, bad); }, "outlier threshold");
  bad = FitOptions{};
  bad.max_iterations = -3;
  ExpectInputError([&] { FitErrorsInVariables({d.x, d.y, d.u_y, d.u_y}, bad); }, "fit options");
  RobustOptions robust;
  robust.loss_scale = -1.0;
  ExpectInputError([&] { FitRobust(d, robust); }, "loss scale");
}

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
