// Shared by the fit tests (tests/fit_*_test.cpp): the certified and published data sets read from
// tests/data, synthetic lines, and the assertions every fit test uses.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fit/least_squares_line.hpp"
#include "model/input_error.hpp"
#include "oracle/line_references.hpp"

namespace uphill::testing {

// Whitespace-separated numeric columns of tests/data/<file>; lines starting with '#' are comments.
std::vector<std::vector<double>> ReadColumns(const std::string& file, std::size_t columns);

// |actual − expected| ≤ rel·|expected|, i.e. agreement to about −log10(rel) significant digits.
::testing::AssertionResult RelNear(double actual, double expected, double rel);

// NIST StRD "Norris" (tests/data/nist_norris.dat): 36 rows, no uncertainties.
LineData Norris();
// Pearson's data with York's weights (tests/data/pearson_york.dat): u = 1/sqrt(w).
LineData PearsonYork();
// Y = c + k·X + noise with per-row u(Y) (and u(X) when errors_in_x: X observed with noise).
LineData Synthetic(std::size_t n, double k, double c, std::uint64_t seed, bool errors_in_x);
// Twenty rows on Y = 2 + 0.5·X with σ = 0.1 noise, row 13 moved by 50 σ.
LineData TwentyRowsWithOneOutlier(bool with_u);

// The fit's parameters, covariance and χ² against an independent reference of src/oracle.
void ExpectMatchesClosed(const FitReport& fit, const oracle::LineSolution& closed, double rel_values,
                         double rel_covariance);

// f() throws InputError about `quantity`, with a rule.
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

}  // namespace uphill::testing
