// Experiment folders (data/README.md, format uphill-experiment/1): the samples load, and every
// kind of bad input is named with file, row, column and rule while the other rows survive.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "experiment_test_support.hpp"
#include "io/experiment.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

const std::string kSamples = std::string(UPHILL_SOURCE_DIR) + "/data";

std::string MakeExperiment(const std::string& name, const std::string& json, const std::string& csv) {
  const auto dir = std::filesystem::temp_directory_path() / ("uphill_exp_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "experiment.json") << json;
  std::ofstream(dir / "measurements.csv") << csv;
  return dir.string();
}

const char* kJson = R"({"format": "uphill-experiment/1", "body": {"type": "spheroid", "a": "15.875 mm",
  "b": "25.4 mm"}, "apparatus": {"H": "300 mm"}, "uncertainties": {"L": "2 mm", "D": "0.5 mm", "Y": "1.5 mm"}})";

TEST(Experiment, SampleSeriesLoadCompletely) {
  const Experiment e = LoadExperiment(kSamples + "/series2-fixed-L");
  ASSERT_EQ(e.rows.size(), 24u);
  EXPECT_TRUE(e.Errors().empty());
  const ExperimentRow& first = e.rows.front();
  EXPECT_EQ(first.row, 2);
  EXPECT_EQ(first.trial, "s2-1");
  ASSERT_TRUE(first.configuration.has_value());
  EXPECT_DOUBLE_EQ(first.configuration->H.value, 0.3);
  EXPECT_DOUBLE_EQ(first.configuration->H.u, 0.0005);
  EXPECT_DOUBLE_EQ(first.configuration->D.u, 0.0002);
  EXPECT_DOUBLE_EQ(first.Y.u, 0.0005);
  EXPECT_GT(first.Y.value, 0.5);  // D = 110 mm: X = 534.5 mm
  EXPECT_NE(e.notes.find("SYNTHETIC DATA"), std::string::npos);
  EXPECT_EQ(LoadExperiment(kSamples + "/series1-fixed-D").UsableRows().size(), 21u);
}

TEST(Experiment, PerRowUncertaintiesOverrideTheDefaults) {
  const Experiment e = LoadExperiment(MakeExperiment(
      "override", kJson, "trial,L_mm,D_mm,Y_mm,u_Y_mm\nt1,1165,150,390,0.7\nt2,1165,150,391,\n"));
  ASSERT_TRUE(e.Errors().empty()) << e.Errors().front();
  EXPECT_DOUBLE_EQ(e.rows[0].Y.u, 0.0007);
  EXPECT_DOUBLE_EQ(e.rows[1].Y.u, 0.0015);  // empty cell: the default
}

// The `excluded` column (data/README.md): optional, text, its trimmed cell the reason; blank
// means fitted. Truth: the format's rules as data/README.md states them.
TEST(Experiment, TheExcludedColumnKeepsEachRowsReason) {
  const Experiment e = LoadExperiment(MakeExperiment(
      "excluded", kJson,
      "trial,L_mm,D_mm,Y_mm,excluded\nt1,1165,150,390,\nt2,1165,150,39.1,\"  Y typed in cm, 1 row  \"\nt3,1165,150,391,   \n"));
  ASSERT_TRUE(e.Errors().empty()) << e.Errors().front();
  EXPECT_EQ(e.rows[0].excluded, "");
  EXPECT_EQ(e.rows[1].excluded, "Y typed in cm, 1 row");
  EXPECT_EQ(e.rows[2].excluded, "");  // blanks only: fitted
  EXPECT_EQ(e.UsableRows().size(), 3u);  // excluded rows are still analysed (shown, not fitted)
  // In a version-1 folder too, and without the column nothing is excluded (the samples).
  for (const ExperimentRow& r : LoadExperiment(kSamples + "/series2-fixed-L").rows) EXPECT_EQ(r.excluded, "");
  // A text column: a unit in its header is refused, naming it.
  EXPECT_NE(LoadError(MakeExperiment("excluded-unit", kJson, "trial,L_mm,D_mm,Y_mm,excluded_mm\nt1,1165,150,390,x\n"))
                .find("column excluded_mm: 'excluded' is text: its header has no unit"),
            std::string::npos);
}

TEST(Experiment, BadRowsAreNamedAndTheOthersKept) {
  const std::string dir = MakeExperiment("badrows", kJson,
                                         "trial,L_mm,D_mm,Y_mm,note\n"
                                         "t1,1165,150,390,ok\n"
                                         "t1,1165,150,391,duplicate label\n"
                                         "t3,1165,,392,empty D\n"
                                         "t4,1165,150,abc,text Y\n"
                                         "t5,1165,-150,390,negative D\n"
                                         "t6,1165,150,390,ok\n");
  const Experiment e = LoadExperiment(dir);
  ASSERT_EQ(e.rows.size(), 6u);
  const auto errors = e.Errors();
  ASSERT_EQ(errors.size(), 4u);
  const std::string csv = dir + "/measurements.csv";
  EXPECT_EQ(errors[0], csv + ", row 3, column trial: duplicate trial label 't1'");
  EXPECT_EQ(errors[1], csv + ", row 4, column D_mm: is empty (expected a number with a unit)");
  EXPECT_EQ(errors[2], csv + ", row 5, column Y_mm: 'abc' is not a number");
  EXPECT_EQ(errors[3], csv + ", row 6, column D_mm: must be > 0 (got -0.14999999999999999)");
  EXPECT_EQ(e.UsableRows().size(), 2u);
  EXPECT_EQ(e.UsableRows()[1]->trial, "t6");
  // Where a page marks each error, and the cells kept for a row check (SI, from the CSV's text).
  EXPECT_EQ(e.rows[1].error_column, "trial");
  EXPECT_EQ(e.rows[2].error_column, "D");
  EXPECT_EQ(e.rows[3].error_column, "Y");
  EXPECT_EQ(e.rows[4].error_column, "D");
  EXPECT_EQ(e.rows[0].error_column, "");
  EXPECT_DOUBLE_EQ(e.rows[4].cells.at("D"), -0.15);
  EXPECT_DOUBLE_EQ(e.rows[3].cells.at("L"), 1.165);
  EXPECT_EQ(e.rows[3].cells.count("Y"), 0u);  // 'abc'
  EXPECT_EQ(e.rows[2].cells.count("D"), 0u);  // empty
  EXPECT_EQ(e.column_units.at("D"), "mm");
}

TEST(Experiment, FolderLevelProblemsThrowWithTheFileAndKey) {
  EXPECT_EQ(LoadError("/nonexistent/exp"), "/nonexistent/exp: is not an experiment folder");
  std::string dir = MakeExperiment("fmt", R"({"format": "uphill-experiment/9", "body": {}})", "trial,Y_mm\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json: format: must be \"uphill-experiment/1\" or \"uphill-experiment/2\" (got \"uphill-experiment/9\")");
  dir = MakeExperiment("json", "{not json", "trial,Y_mm\n");
  EXPECT_NE(LoadError(dir).find(dir + "/experiment.json: is not valid JSON"), std::string::npos);
  dir = MakeExperiment("key", R"({"format": "uphill-experiment/1", "body": {"type": "sphere", "R": "1 mm"},
    "aparatus": {}})", "trial,Y_mm\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json.aparatus: unknown key");
  dir = MakeExperiment("twice", kJson, "trial,L_mm,H_mm,D_mm,Y_mm\nt,1,2,3,4\n");
  EXPECT_EQ(LoadError(dir), dir + "/measurements.csv, row 1, column H_mm: 'H' is also a constant in "
                                  "experiment.json (apparatus.H): give it in one place only");
  dir = MakeExperiment("noy", kJson, "trial,L_mm,D_mm\nt,1,2\n");
  EXPECT_EQ(LoadError(dir), dir + "/measurements.csv, row 1: column 'Y' is missing");
  dir = MakeExperiment("unknown", kJson, "trial,L_mm,D_mm,Y_mm,Z_mm\nt,1,2,3,4\n");
  EXPECT_EQ(LoadError(dir), dir + "/measurements.csv, row 1, column Z_mm: unknown column (see data/README.md)");
  dir = MakeExperiment("empty", kJson, "");
  EXPECT_EQ(LoadError(dir), dir + "/measurements.csv: is empty (expected a header row)");
}

TEST(Experiment, UnitsMustMatchTheQuantity) {
  const std::string dir = MakeExperiment("units", kJson, "trial,L_mm,D_deg,Y\nt1,1165,150,390mm\nt2,1165,150,390\n");
  const Experiment e = LoadExperiment(dir);
  ASSERT_EQ(e.Errors().size(), 2u);
  EXPECT_EQ(e.Errors()[0], dir + "/measurements.csv, row 2, column D_deg: unit 'deg' is not accepted here "
                                 "(accepted: mm, cm, m, km, um, in)");
  EXPECT_EQ(e.Errors()[1], dir + "/measurements.csv, row 3, column D_deg: unit 'deg' is not accepted here "
                                 "(accepted: mm, cm, m, km, um, in)");
}

// Regression tests for what fuzzing the readers found (tests/fuzz, scripts/fuzz.sh).

TEST(FuzzRegression, BodyWithoutTypeIsAnInputError) {
  // nlohmann::json's out_of_range ("key 'type' not found") escaped: `uphill fit` ended as an
  // internal error.
  const std::string dir = MakeExperiment(
      "notype", R"({"format": "uphill-experiment/1", "body": {"R": "12.7 mm"}, "apparatus": {"H": "300 mm"}})",
      "trial,L_mm,D_mm,Y_mm\nt1,1165,150,390\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json: body.type: is missing (sphere, spheroid or double-cone)");
}

TEST(FuzzRegression, DeeplyNestedJsonValuesAreRefusedWithoutRecursion) {
  // A value nested 10^5 deep must not be dumped into the error message once per level (that
  // recursion overflows the stack).
  // Values of body, apparatus and uncertainties must be strings even when no row uses them, as
  // the metadata is copied (recursively) into fit.json.
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  std::string dir = MakeExperiment(
      "deep_notes", R"({"format": "uphill-experiment/1", "notes": [)" + deep + R"(], "body": {"type": "sphere", "R": "1 mm"}})",
      "trial,Y_mm\nt,5\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json: notes: must be a string with a unit, e.g. \"300 mm\" (got an array)");
  dir = MakeExperiment("deep_format", R"({"format": )" + deep + "}", "trial,Y_mm\nt,5\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json: format: must be \"uphill-experiment/1\" or \"uphill-experiment/2\" (got an array)");
  dir = MakeExperiment("deep_unused", std::string(R"({"format": "uphill-experiment/1", "body": {"type": "spheroid",)") +
                                          R"( "a": "15.875 mm", "b": "25.4 mm"}, "apparatus": {"H": "300 mm"},)" +
                                          R"( "uncertainties": {"h": )" + deep + "}}",
                       "trial,L_mm,D_mm,Y_mm\nt1,1165,150,390\n");
  EXPECT_EQ(LoadError(dir), dir + "/experiment.json: uncertainties.h: must be a string with a unit, e.g. \"300 mm\" (got an array)");
}

}  // namespace
}  // namespace uphill::testing
