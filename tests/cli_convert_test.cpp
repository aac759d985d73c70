// `uphill convert` end to end: the stable JSON keys and their values against the model, units at
// the edges, batches with bad rows, and exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <cstdio>
#include <algorithm>
#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "model/scene.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

using nlohmann::json;
using testing::RunUphill;

TEST(ConvertCli, JsonOfTheLabCaseMatchesTheReference) {
  // lab_exp2_L1165_H300_D100 of the 60-digit reference, entered as a technician would.
  const auto r = RunUphill(
      "convert --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 100mm --mu 0.01 "
      "--json --at-x 300mm");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  const json& ref = testing::ReferenceCase("lab_exp2_L1165_H300_D100").at("outputs");
  EXPECT_REF(j.at("theta").get<double>(), ref.at("theta"), 1.0);
  EXPECT_REF(j.at("alpha").get<double>(), ref.at("alpha"), 1.0);
  EXPECT_REF(j.at("phi").get<double>(), ref.at("phi"), 1.0);
  EXPECT_REF(j.at("x_eq").get<double>(), ref.at("x_eq"), 4.0);
  EXPECT_REF(j.at("x_max").get<double>(), ref.at("x_max"), 4.0);
  EXPECT_REF(j.at("x_rest").get<double>(), ref.at("rest")[1].at("x_rest"), 4.0);
  EXPECT_REF(j.at("x_rest_low").get<double>(), ref.at("rest")[1].at("x_rest_low"), 1e3);
  EXPECT_EQ(j.at("rolls_up"), true);
  EXPECT_EQ(j.at("x_eq_beyond_crossbar"), false);
  ASSERT_EQ(j.at("points").size(), 1u);
  EXPECT_EQ(j.at("points")[0].at("x").get<double>(), 0.3);
  for (const char* key : {"z", "dzdx", "R_star", "x_M"}) EXPECT_TRUE(j.at("points")[0].contains(key)) << key;
  EXPECT_FALSE(j.contains("u_x_eq"));  // no input uncertainty, no uncertainty keys
}

TEST(ConvertCli, InchesAndAnglesGiveTheSameNumbersAsMillimetres) {
  const auto mm = RunUphill("convert --body sphere --R 12.7mm --theta 10deg --alpha 30deg --json");
  const auto in = RunUphill("convert --body sphere --R 0.5in --theta 0.17453292519943295rad "
                            "--alpha 30deg --json");
  ASSERT_EQ(mm.status, 0) << mm.err;
  ASSERT_EQ(in.status, 0) << in.err;
  EXPECT_DOUBLE_EQ(json::parse(mm.out).at("x_eq").get<double>(), json::parse(in.out).at("x_eq").get<double>());
}

TEST(ConvertCli, UncertaintiesAreReportedBothWaysAndFlaggedWhenTheyDisagree) {
  // D = 45 mm puts X within 0.12 % of x_max: X is strongly nonlinear in D over ±u(D).
  const auto r = RunUphill(
      "convert --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 45mm --u-D 1mm "
      "--mc-trials 20000 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_GT(j.at("u_x_eq").get<double>(), 0.0);
  EXPECT_GT(j.at("u_mc_x_eq").get<double>(), 0.0);
  EXPECT_EQ(j.at("u_theta").get<double>(), 0.0);  // θ = atan(H/L) does not depend on D
  EXPECT_EQ(j.at("x_eq_beyond_crossbar"), true);
  const auto interval = j.at("u_mc_x_eq_interval");
  EXPECT_LT(interval[0].get<double>(), j.at("x_eq").get<double>());
  EXPECT_GT(interval[1].get<double>(), j.at("x_eq").get<double>());
  // A near-linear setting agrees to well within 5 %.
  const auto lin = RunUphill(
      "convert --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 150mm --u-D 0.1mm "
      "--mc-trials 20000 --json");
  const json k = json::parse(lin.out);
  EXPECT_NEAR(k.at("u_mc_x_eq").get<double>() / k.at("u_x_eq").get<double>(), 1.0, 0.03);
  EXPECT_EQ(k.at("uncertainty_disagrees"), false);
}

TEST(ConvertCli, VerdictsInPlainLanguage) {
  const auto beyond = RunUphill("convert --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 45mm");
  EXPECT_NE(beyond.out.find("X lies beyond the crossbar (L = 1165 mm from O, horizontally): this "
                            "apparatus cannot show the effect."),
            std::string::npos)
      << beyond.out;
  const auto down = RunUphill("convert --body double-cone --R 50mm --h 100mm --theta 20deg --alpha 60deg");
  EXPECT_NE(down.out.find("the double cone rolls down everywhere"), std::string::npos) << down.out;
  const auto up = RunUphill("convert --body double-cone --R 50mm --h 100mm --theta 5deg --alpha 60deg");
  EXPECT_NE(up.out.find("the double cone rolls up"), std::string::npos) << up.out;
}

TEST(ConvertCli, BadFlagsExitWithStatusTwoAndNameTheFlag) {
  const struct {
    const char* args;
    const char* message;
  } cases[] = {
      {"convert --body sphere --R 12.7 --theta 10deg --alpha 30deg",
       "uphill: --R: '12.7' has no unit (accepted: mm, cm, m, km, um, in)\n"},
      {"convert --body sphere --R -1mm --theta 10deg --alpha 30deg", "uphill: --R: must be > 0 (got -0.001)\n"},
      {"convert --body sphere --R nan --theta 10deg --alpha 30deg", "uphill: --R: 'nan' is not a finite number\n"},
      {"convert --body cube --R 1mm --theta 10deg --alpha 30deg",
       "uphill: --body: unknown body 'cube' (accepted: sphere, spheroid, double-cone)\n"},
      {"convert --body sphere --R 1mm --theta 95deg --alpha 30deg",
       "uphill: --theta: must lie in [0, 90) deg (got 1.6580627893946132 rad)\n"},
      {"convert --body sphere --R 1mm --L 1m --H 0.3m", "uphill: --D: is missing (rail separation at the crossbar)\n"},
  };
  for (const auto& c : cases) {
    const auto r = RunUphill(c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_EQ(r.err, c.message) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
  }
}

TEST(ConvertCli, BatchReportsBadRowsAndConvertsTheOthers) {
  const std::string csv =
      "label,body,R_mm,L_mm,H_mm,D_mm\n"
      "good,sphere,12.7,1165,300,100\n"
      "negative,sphere,12.7,1165,300,-5\n"
      "text,sphere,12.7,1165,abc,100\n"
      "short,sphere,12.7\n"
      "also good,sphere,12.7,900,300,100\n";
  const auto r = RunUphill("convert --batch - --json", csv);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err,
            "uphill: <stdin>, row 3, column D_mm: must be > 0 (got -0.0050000000000000001)\n"
            "uphill: <stdin>, row 4, column H_mm: 'abc' is not a number\n"
            "uphill: <stdin>, row 5: has 3 fields, the header has 6\n");
  const json j = json::parse(r.out);
  ASSERT_EQ(j.size(), 5u);
  EXPECT_EQ(j[0].at("row"), 2);
  EXPECT_TRUE(j[0].contains("x_eq"));
  EXPECT_TRUE(j[1].contains("error"));
  EXPECT_FALSE(j[1].contains("x_eq"));  // never a NaN or a made-up number for a bad row
  EXPECT_EQ(j[4].at("label"), "also good");
  EXPECT_TRUE(j[4].contains("x_eq"));
}

TEST(ConvertCli, BatchRefusesUnknownColumnsAndEmptyFiles) {
  const auto unknown = RunUphill("convert --batch -", "body,R_mm,L_mm,H_mm,D_mmm\nsphere,1,2,3,4\n");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(unknown.err,
            "uphill: <stdin>, row 1, column D_mmm: unknown column (see docs/convert.md, 'Batch "
            "CSV', for the accepted names)\n");
  const auto empty = RunUphill("convert --batch -", "");
  EXPECT_EQ(empty.status, 2);
  EXPECT_EQ(empty.err, "uphill: <stdin>: is empty (expected a header row)\n");
  const auto missing = RunUphill("convert --batch /nonexistent/runs.csv");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.err, "uphill: /nonexistent/runs.csv: cannot be opened for reading\n");
}

TEST(ConvertCli, FlagsAreDefaultsForBatchColumnsAndCsvNamesItsUnits) {
  const auto r = RunUphill("convert --batch - --body spheroid --a 15.875mm --b 25.4mm --H 300mm --csv "
                           "--length-unit in",
                           "L_mm,D\n1165,100mm\n1165,4in\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')),
            "row,body,theta_deg,alpha_deg,phi_deg,X_in,x_max_in,rolls_up,note,error");
  // Row 3 has D = 4 in = 101.6 mm: a little smaller X than row 2's 100 mm.
  EXPECT_NE(r.out.find("\n2,spheroid,14.44"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n3,spheroid,14.44"), std::string::npos) << r.out;
}

// The whole CSV output and stderr of a batch whose numeric rows take the block path, against the
// same rows sent through the full path (an empty label column in front, which the block path does
// not take; its column removed from the output): good rows, rows with X beyond the crossbar, bad
// cells, a short row, an empty cell filled from the flags, over more rows than one block.
// Truth: the full path's output, byte for byte.
TEST(ConvertCli, BatchCsvOfNumericRowsIsTheFullPathsOutput) {
  std::string numeric = "L_mm,H_mm,D_mm\n", labelled = "label,L_mm,H_mm,D_mm\n";
  const std::vector<std::string> odd = {"1165,-3,100", "1165,abc,100", "1165,300", "0,300,100", "1165,,100",
                                        "1165,300,1e999", "1165,0,100", "1e-300,300,100"};
  for (int i = 0; i < 5000; ++i) {
    std::string row;
    if (i % 211 == 17) {
      row = odd[static_cast<std::size_t>(i / 211) % odd.size()];
    } else {
      char text[64];
      const long long k = i;
      std::snprintf(text, sizeof text, "%.2f,%.2f,%.2f", 500.0 + static_cast<double>(k * 7919 % 150000) / 100.0,
                    1.0 + static_cast<double>(k * 104729 % 49900) / 100.0,
                    20.0 + static_cast<double>(k * 15485863 % 23000) / 100.0);
      row = text;
    }
    numeric += row + "\n";
    labelled += "," + row + "\n";
  }
  const std::string flags = "--body spheroid --a 15.875mm --b 25.4mm --H 250mm --csv";
  const auto fast = RunUphill("convert --batch - " + flags, numeric);
  const auto full = RunUphill("convert --batch - " + flags, labelled);
  EXPECT_EQ(fast.status, 2);
  EXPECT_EQ(full.status, 2);
  // The short row's message counts the label column too.
  const auto counted = [](std::string text) {
    for (std::size_t at; (at = text.find("has 3 fields, the header has 4")) != std::string::npos;)
      text.replace(at, 30, "has 2 fields, the header has 3");
    return text;
  };
  EXPECT_EQ(fast.err, counted(full.err));
  EXPECT_GE(std::count(fast.err.begin(), fast.err.end(), '\n'), 15);
  // Drop the (empty) label column: the second field of every line.
  std::string without_label;
  std::istringstream lines(full.out);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t first = line.find(',');
    without_label += line.erase(first, line.find(',', first + 1) - first) + "\n";
  }
  EXPECT_EQ(fast.out.substr(0, fast.out.find('\n')), "row,body,theta_deg,alpha_deg,phi_deg,X_mm,x_max_mm,rolls_up,note,error");
  EXPECT_EQ(fast.out, counted(without_label));
  EXPECT_NE(fast.out.find(",yes,X beyond crossbar,\n"), std::string::npos);
  EXPECT_EQ(std::count(fast.out.begin(), fast.out.end(), '\n'), 5001);
}

}  // namespace
}  // namespace uphill::testing
