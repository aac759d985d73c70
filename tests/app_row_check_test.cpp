// The one row check (app/row_check.hpp, rules in report/row_check.hpp): each flag raised on the
// row it is written for and not on a good row, and the report's analysis carrying the same flags.
// Truth: X from the closed form of docs/physics.md ("Lab shortcut", horizontal L:
// X = L·(2b/D)/√(1 + (a·D/(2b·H))²)), computed here without the model; the thresholds (2u, 3u and
// 20 %, the unit factors, the plausible ranges) from report/row_check.hpp's contract; u(X) is the
// check's own first-order value (model/propagation.hpp, tested against its references in
// propagation_test), so the threshold tests sit either side of 2u.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "app/row_check.hpp"
#include "file_test_support.hpp"
#include "io/experiment.hpp"
#include "model/input_error.hpp"
#include "report/analysis.hpp"

namespace uphill::testing {
namespace {

// The lab spheroid (2 × 1.25 × 1.25 inch, long axis across the rails), H = 300 mm, horizontal L.
const char* kJson = R"({"format": "uphill-experiment/1", "body": {"type": "spheroid", "a": "15.875 mm",
  "b": "25.4 mm"}, "apparatus": {"H": "300 mm", "L_convention": "horizontal"},
  "uncertainties": {"L": "1 mm", "H": "0.5 mm", "D": "0.2 mm", "Y": "0.5 mm"}})";

double ClosedFormX(double L, double D) {  // mm
  const double a = 15.875, b = 25.4, H = 300;
  return L * (2 * b / D) / std::sqrt(1 + std::pow(a * D / (2 * b * H), 2));
}

Experiment Load(const std::string& name, const std::string& rows) {
  const auto dir = FreshFolder("row-check-" + name);
  std::ofstream(dir / "experiment.json") << kJson;
  std::ofstream(dir / "measurements.csv") << "trial,L_mm,D_mm,Y_mm\n" << rows;
  return LoadExperiment(dir.string());
}

std::vector<std::string> Codes(const RowCheck& c) {
  std::vector<std::string> codes;
  for (const RowFlag& f : c.flags) codes.push_back(f.code);
  return codes;
}

std::string Text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// The issue's case: D = 165 mm, Y = 270 mm with L = 906 mm gives X = 274.9 mm, Y − X = −4.9 mm.
TEST(RowCheck, YBelowXBeyondTwoUncertaintiesCannotBeARestPosition) {
  const Experiment e = Load("below", "t1,906,165,270\nt2,906,165,276\n");
  const RowCheck c = CheckRow(e, e.rows[0]);
  ASSERT_TRUE(c.x_eq && c.u_x_eq && c.y && c.u_y);
  EXPECT_NEAR(*c.x_eq * 1e3, ClosedFormX(906, 165), 1e-9);
  EXPECT_NEAR(*c.x_eq * 1e3, 274.907, 1e-3);
  const double u = std::hypot(*c.u_x_eq, *c.u_y);
  ASSERT_LT(2 * u, 4.9e-3);  // the case is beyond 2u
  ASSERT_EQ(Codes(c), std::vector<std::string>{"y_below_x"});
  EXPECT_EQ(c.flags[0].field, "Y");
  EXPECT_EQ(c.flags[0].severity, FlagSeverity::kWarning);
  EXPECT_NE(c.flags[0].message.find("Y − X = -4.907 mm"), std::string::npos) << c.flags[0].message;
  EXPECT_NE(c.flags[0].message.find("the body cannot rest there"), std::string::npos);
  EXPECT_TRUE(CheckRow(e, e.rows[1]).flags.empty());  // Y beyond X: a rest position
}

TEST(RowCheck, TheBelowXThresholdIsTwoCombinedUncertainties) {
  const Experiment probe = Load("probe", "t1,906,165,275\n");
  const RowCheck p = CheckRow(probe, probe.rows[0]);
  const double x = *p.x_eq * 1e3, two_u = 2e3 * std::hypot(*p.u_x_eq, *p.u_y);
  const Experiment e =
      Load("threshold", "in,906,165," + Text(x - 0.95 * two_u) + "\nout,906,165," + Text(x - 1.05 * two_u) + "\n");
  EXPECT_TRUE(CheckRow(e, e.rows[0]).flags.empty());
  EXPECT_EQ(Codes(CheckRow(e, e.rows[1])), std::vector<std::string>{"y_below_x"});
}

TEST(RowCheck, YTypedInCentimetresIsAUnitMixUpNotAPosition) {
  // Y = 27.55 in a mm column: a tenth of a Y just beyond X (the ratio 1/10 of the contract).
  const Experiment e = Load("cm", "t1,906,165,27.55\n");
  const RowCheck c = CheckRow(e, e.rows[0]);
  ASSERT_EQ(Codes(c), std::vector<std::string>{"unit_mixup"});  // not also y_below_x or y_far
  EXPECT_EQ(c.flags[0].field, "Y");
  EXPECT_NE(c.flags[0].message.find("looks like cm typed in a mm column"), std::string::npos) << c.flags[0].message;
}

TEST(RowCheck, EachFlagOnItsRow) {
  // L = 1165 mm: D = 150 → X = 389.8 mm (closed form), x_max = 394.9 mm.
  const double x150 = ClosedFormX(1165, 150);
  const Experiment e = Load("each",
                            "good,1165,150," + Text(x150 + 1) +
                                "\n"
                                "far,1165,150," + Text(1.3 * x150) +
                                "\n"
                                "falls,1165,200,900\n"
                                "crossbar,1165,45,1300\n"  // the paper's D: X beyond the crossbar
                                "inches,1165,5.9," + Text(x150 + 2) +  // D typed in inches (150 mm)
                                "\n"
                                "long,9000,150,400\n"
                                "text,1165,abc,400\n"
                                "twice,1165,150," + Text(x150 + 1) + "\ngood,1165,160,380\n");
  const std::vector<RowCheck> checks = CheckRows(e);
  ASSERT_EQ(checks.size(), e.rows.size());
  const auto codes = [&](std::size_t i) { return Codes(checks[i]); };
  EXPECT_EQ(codes(0), (std::vector<std::string>{"duplicate_trial", "duplicate_row"}));
  // 30 % beyond X: far (> 20 % and > 3u), and also beyond x_max (5 mm beyond X).
  EXPECT_EQ(codes(1), (std::vector<std::string>{"y_far", "y_beyond_fall_off"}));
  EXPECT_TRUE(checks[2].Has("y_beyond_fall_off")) << checks[2].flags.size();
  EXPECT_TRUE(checks[3].Has("x_beyond_crossbar"));
  EXPECT_TRUE(checks[4].Has("unit_mixup"));
  EXPECT_EQ(checks[4].flags[0].field, "D");
  EXPECT_TRUE(checks[5].Has("implausible"));
  EXPECT_EQ(checks[5].flags[0].field, "L");
  ASSERT_TRUE(checks[6].Has("invalid"));
  EXPECT_EQ(checks[6].flags[0].field, "D");
  EXPECT_EQ(checks[6].flags[0].severity, FlagSeverity::kError);
  EXPECT_NE(checks[6].flags[0].message.find("measurements.csv, row 8, column D_mm"), std::string::npos)
      << checks[6].flags[0].message;
  EXPECT_EQ(codes(7), std::vector<std::string>{"duplicate_row"});
  // The reader leaves the later "good" out: one error flag says so, not a second `invalid`.
  ASSERT_EQ(codes(8), std::vector<std::string>{"duplicate_trial"});
  EXPECT_EQ(checks[8].flags[0].severity, FlagSeverity::kError);
}

TEST(RowCheck, TheReportCarriesTheSameFlags) {
  const Experiment e = Load("report", "t1,906,165,270\nt2,906,180,260\nt3,906,200,27.2\nt4,906,150,310\n");
  AnalysisOptions options;
  options.mc_trials = 0;
  const ExperimentAnalysis a = AnalyseExperiment(e, options);
  ASSERT_EQ(a.rows.size(), 4u);
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    const RowCheck c = CheckRow(e, e.rows[i]);
    ASSERT_EQ(a.rows[i].flags.size(), c.flags.size()) << i;
    for (std::size_t k = 0; k < c.flags.size(); ++k) {
      EXPECT_EQ(a.rows[i].flags[k].code, c.flags[k].code);
      EXPECT_EQ(a.rows[i].flags[k].message, c.flags[k].message);
    }
  }
  EXPECT_TRUE(CheckRow(e, e.rows[0]).Has("y_below_x"));
  EXPECT_TRUE(CheckRow(e, e.rows[2]).Has("unit_mixup"));
}

TEST(RowCheck, TheJsonOfThePageAndPython) {
  const Experiment e = Load("json", "t1,906,165,270\n");
  const RowCheck c = CheckRow(e, e.rows[0]);
  const nlohmann::ordered_json mm = RowCheckJson(c, "mm");
  EXPECT_NEAR(mm["x"].get<double>(), ClosedFormX(906, 165), 1e-9);
  EXPECT_NEAR(mm["residual"].get<double>(), 270 - ClosedFormX(906, 165), 1e-9);
  EXPECT_EQ(mm["flags"][0]["code"], "y_below_x");
  EXPECT_EQ(mm["flags"][0]["severity"], "warning");
  EXPECT_NE(mm["flags"][0]["message"].get<std::string>().find("Y − X = -4.907 mm"), std::string::npos);
  EXPECT_NEAR(RowCheckJson(c, "m")["x"].get<double>(), ClosedFormX(906, 165) / 1e3, 1e-12);
  EXPECT_THROW(RowCheckJson(c, "furlong"), InputError);
}

}  // namespace
}  // namespace uphill::testing
