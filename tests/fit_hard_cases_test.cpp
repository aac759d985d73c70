// The straight-line fits' hard cases: too few rows, all X equal, non-finite values, missing
// uncertainties, two rows, invalid options. Truth: the rules of src/fit's headers (each refusal
// names its quantity) and the exact line through two points.
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

}  // namespace
}  // namespace uphill::testing
