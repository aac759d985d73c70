// The streamed JSON of `uphill fit --xy --json` (WriteFitJson, per-row entries computed on
// demand, fit/line_rows.hpp) parses to exactly the JSON tree of the in-memory result
// (FitToJson of the same fit with its rows kept): a round trip through nlohmann::json on
// small N for every line method, rows and all, and with the rows left out (--no-rows).
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "fit/least_squares_line.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "report/fit_json.hpp"

namespace uphill::testing {
namespace {

LineData Rows(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> t(0.0, 10.0), u(0.05, 0.3);
  std::normal_distribution<double> noise;
  LineData d;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = t(rng), uy = u(rng), ux = 0.3 * u(rng);
    d.x.push_back(x + ux * noise(rng));
    d.y.push_back(0.5 - 1.25 * x + uy * noise(rng) + (i % 17 == 0 ? 8 * uy : 0.0));
    d.u_x.push_back(ux);
    d.u_y.push_back(uy);
  }
  return d;
}

nlohmann::json WithoutTimes(nlohmann::json j) {
  j["solver"].erase("seconds");  // Ceres' wall time differs between two runs
  return j;
}

TEST(FitJsonStream, ParsesToTheInMemoryTree) {
  const LineData d = Rows(257, 3);
  FitOptions keep, stream;
  stream.keep_rows = false;
  RobustOptions robust_keep, robust_stream;
  robust_stream.fit.keep_rows = false;
  const std::vector<std::pair<FitReport, FitReport>> fits = {
      {FitOrdinaryLeastSquares(d, keep), FitOrdinaryLeastSquares(d, stream)},
      {FitWeightedLeastSquares(d, keep), FitWeightedLeastSquares(d, stream)},
      {FitErrorsInVariables(d, keep), FitErrorsInVariables(d, stream)},
      {FitRobust(d, robust_keep), FitRobust(d, robust_stream)}};
  for (const auto& [kept, streamed] : fits) {
    SCOPED_TRACE(MethodName(kept.method));
    const nlohmann::json expected = nlohmann::json::parse(FitToJson(kept).dump(2));
    ASSERT_EQ(expected.at("rows").size(), d.size());
    std::ostringstream out;
    WriteFitJson(out, streamed, d);
    const nlohmann::json got = nlohmann::json::parse(out.str());
    EXPECT_EQ(WithoutTimes(got), WithoutTimes(expected));
    // A report that kept its rows streams them too, the same.
    std::ostringstream from_kept;
    WriteFitJson(from_kept, kept, d);
    EXPECT_EQ(WithoutTimes(nlohmann::json::parse(from_kept.str())), WithoutTimes(expected));
    // --no-rows: everything but the per-row entries.
    std::ostringstream no_rows;
    WriteFitJson(no_rows, streamed, d, false);
    nlohmann::json without = WithoutTimes(expected);
    without["rows"] = nlohmann::json::array();
    EXPECT_EQ(WithoutTimes(nlohmann::json::parse(no_rows.str())), without);
  }
}

}  // namespace
}  // namespace uphill::testing
