// The page's row check through the HTTP API (src/server/row_check.hpp), driven as server_test is:
// an in-process server on a free loopback port.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "file_test_support.hpp"
#include "io/experiment.hpp"
#include "server/row_check.hpp"
// Last: it includes <httplib.h>, which includes <resolv.h>, whose `_res` macro breaks Eigen.
#include "server_test_support.hpp"

namespace uphill::testing {
namespace {

using ServerRowCheckTest = ServerFixture;

// The page and `uphill fit` share one row check (app/row_check.hpp): the Y on the wrong
// side of X (L = 906 mm, D = 165 mm: X = 274.9 mm by the closed form of docs/physics.md, "Lab
// shortcut"; Y = 270 mm) and a Y typed in cm are flagged by /api/check, by the state, and by the
// check of the folder the server wrote, read as `uphill fit` reads it, with the same code and words.
TEST_F(ServerRowCheckTest, FlagsRowsAsTheReportDoes) {
  Create();
  const auto row = [](const std::string& trial, const std::string& D, const std::string& Y) {
    return json{{"trial", trial}, {"series", "s"}, {"L", "906"}, {"D", D}, {"Y", Y}, {"note", ""}};
  };
  const std::vector<std::pair<json, std::string>> cases = {{row("below", "165", "270"), "y_below_x"},
                                                           {row("cm", "165", "27.55"), "unit_mixup"}};
  for (const auto& [r, code] : cases) {
    auto [status, draft] = Send("POST", "/api/check", {{"row", r}});
    ASSERT_EQ(status, 200) << draft.dump();
    EXPECT_EQ(FlagCodes(draft), std::vector<std::string>{code}) << draft.dump();
    EXPECT_EQ(draft["flags"][0]["field"], "Y");
    Add(r);
  }
  const json state = State();
  const Experiment written = LoadExperiment(dir_.string());
  ASSERT_EQ(written.rows.size(), 2u);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const json& page = state["rows"][i]["check"];
    const RowCheck fit = CheckRow(written, written.rows[i]);
    ASSERT_EQ(fit.flags.size(), 1u);
    ASSERT_EQ(page["flags"].size(), 1u) << page.dump();
    EXPECT_EQ(page["flags"][0]["code"], cases[i].second);
    EXPECT_EQ(page["flags"][0]["code"], fit.flags[0].code);
    EXPECT_EQ(page["flags"][0]["message"], fit.flags[0].message);
  }
  const double x = 906 * (2 * 25.4 / 165) / std::sqrt(1 + std::pow(15.875 * 165 / (2 * 25.4 * 300), 2));
  EXPECT_NEAR(state["rows"][0]["check"]["x"].get<double>(), x, 1e-9);
  EXPECT_NE(state["rows"][0]["check"]["flags"][0]["message"].get<std::string>().find("the body cannot rest there"),
            std::string::npos);
}

// The page's toggle writes a row's `excluded` reason (an ordinary PUT of the row): the row stays,
// checked and flagged, the live fit leaves it out and equals the fit before the row was added (the
// truth: a row not there), measurements.csv carries the reason as `uphill fit` reads it, and Undo
// takes it back, column and all.
TEST_F(ServerRowCheckTest, AnExcludedRowStaysShownButLeavesTheLiveFitUntilUndone) {
  const json three = CreateWithThreeRows();
  const json slip = Row("t4", 200, 29.3);  // Y typed in cm
  const json four = Add(slip);
  ASSERT_EQ(four["fit"]["n"], 4);
  EXPECT_EQ(four["fit"]["excluded"], 0);
  const json stored = four["rows"][3];
  json row = slip;
  row["excluded"] = "  Y typed in cm  ";
  auto [status, excluded] = Send("PUT", "/api/rows/" + std::to_string(stored["id"].get<int>()),
                                 {{"version", four["version"]}, {"row", row}});
  ASSERT_EQ(status, 200) << excluded.dump();
  EXPECT_EQ(excluded["rows"].size(), 4u);
  EXPECT_EQ(excluded["rows"][3]["excluded"], "Y typed in cm");
  EXPECT_EQ(FlagCodes(excluded["rows"][3]["check"]), std::vector<std::string>{"unit_mixup"});
  EXPECT_EQ(excluded["fit"]["n"], 3);
  EXPECT_EQ(excluded["fit"]["excluded"], 1);
  EXPECT_EQ(excluded["fit"]["slope"], three["fit"]["slope"]);
  EXPECT_EQ(excluded["fit"]["intercept"], three["fit"]["intercept"]);
  const Experiment written = LoadExperiment(dir_.string());
  ASSERT_EQ(written.rows.size(), 4u);
  EXPECT_EQ(written.rows[3].excluded, "Y typed in cm");
  EXPECT_EQ(written.rows[2].excluded, "");

  auto [undo_status, undone] = Send("POST", "/api/undo", {{"version", excluded["version"]}});
  ASSERT_EQ(undo_status, 200) << undone.dump();
  EXPECT_FALSE(undone["rows"][3].contains("excluded"));
  EXPECT_EQ(undone["fit"]["n"], 4);
  EXPECT_EQ(ReadBytes(dir_ / "measurements.csv").find("excluded"), std::string::npos);
}

}  // namespace
}  // namespace uphill::testing
