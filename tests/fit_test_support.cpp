#include "fit_test_support.hpp"

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

namespace uphill::testing {

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

void ExpectMatchesClosed(const FitReport& fit, const oracle::LineSolution& closed, double rel_values,
                         double rel_covariance) {
  EXPECT_TRUE(RelNear(fit.slope(), static_cast<double>(closed.k), rel_values));
  EXPECT_TRUE(RelNear(fit.intercept(), static_cast<double>(closed.c), rel_values));
  EXPECT_TRUE(RelNear(fit.covariance(0, 0), static_cast<double>(closed.var_k), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(1, 1), static_cast<double>(closed.var_c), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(0, 1), static_cast<double>(closed.cov_kc), rel_covariance));
  EXPECT_TRUE(RelNear(fit.covariance(1, 0), static_cast<double>(closed.cov_kc), rel_covariance));
  EXPECT_TRUE(RelNear(fit.chi2, static_cast<double>(closed.chi2), 1e-10));
}

}  // namespace uphill::testing
