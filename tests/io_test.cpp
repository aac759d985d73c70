// Units, CSV tables, configurations from named fields, atomic files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/configuration.hpp"
#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

TEST(Units, LengthsAnglesAndAccelerationToSI) {
  EXPECT_DOUBLE_EQ(ParseQuantity("15.875mm", Dimension::kLength, "a"), 0.015875);
  EXPECT_DOUBLE_EQ(ParseQuantity(" 1.25 in ", Dimension::kLength, "a"), 0.03175);
  EXPECT_DOUBLE_EQ(ParseQuantity("1165", Dimension::kLength, "L", "mm"), 1.165);
  EXPECT_DOUBLE_EQ(ParseQuantity("+2.5cm", Dimension::kLength, "L"), 0.025);
  EXPECT_DOUBLE_EQ(ParseQuantity("1e3um", Dimension::kLength, "L"), 1e-3);
  EXPECT_DOUBLE_EQ(ParseQuantity("180deg", Dimension::kAngle, "alpha"), 3.14159265358979323846);
  EXPECT_DOUBLE_EQ(ParseQuantity("0.5rad", Dimension::kAngle, "alpha"), 0.5);
  EXPECT_DOUBLE_EQ(ParseQuantity("9.81m/s2", Dimension::kAcceleration, "g"), 9.81);
  EXPECT_DOUBLE_EQ(ParseQuantity("0.01", Dimension::kDimensionless, "mu"), 0.01);
  // The inch is exactly 25.4 mm: a round trip is exact to the last bit here.
  EXPECT_EQ(ToUnit(0.0254, Dimension::kLength, "in"), 1.0);
}

TEST(Units, RefusesBareNumbersWrongUnitsAndNonFinite) {
  const auto rule = [](const std::string& text, Dimension d) {
    try {
      ParseQuantity(text, d, "D");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(rule("120", Dimension::kLength), "D: '120' has no unit (accepted: mm, cm, m, km, um, in)");
  EXPECT_EQ(rule("120deg", Dimension::kLength),
            "D: unit 'deg' is not accepted here (accepted: mm, cm, m, km, um, in)");
  EXPECT_EQ(rule("10mm", Dimension::kAngle), "D: unit 'mm' is not accepted here (accepted: deg, rad)");
  EXPECT_EQ(rule("nanmm", Dimension::kLength), "D: 'nanmm' is not a finite number");
  EXPECT_EQ(rule("inf mm", Dimension::kLength), "D: 'inf mm' is not a finite number");
  EXPECT_EQ(rule("1e999mm", Dimension::kLength), "D: '1e999mm' is out of the range of a double");
  EXPECT_EQ(rule("", Dimension::kLength), "D: is empty (expected a number with a unit)");
  EXPECT_EQ(rule("mm", Dimension::kLength), "D: 'mm' is not a number");
  EXPECT_EQ(rule("0.1mm", Dimension::kDimensionless), "D: '0.1mm' must be a plain number, without a unit");
}

TEST(Units, SplitsUnitSuffixOfHeaders) {
  EXPECT_EQ(SplitUnitSuffix("L_mm"), (std::pair<std::string, std::string>{"L", "mm"}));
  EXPECT_EQ(SplitUnitSuffix("u_D_in"), (std::pair<std::string, std::string>{"u_D", "in"}));
  EXPECT_EQ(SplitUnitSuffix("rod_diameter"), (std::pair<std::string, std::string>{"rod_diameter", ""}));
  EXPECT_EQ(SplitUnitSuffix("theta_deg"), (std::pair<std::string, std::string>{"theta", "deg"}));
}

TEST(CsvTable, ReadsQuotedFieldsAndNumbersRowsLikeASpreadsheet) {
  std::istringstream in("\xEF\xBB\xBFlabel,L_mm,note\n\"a, b\",1165,\"say \"\"hi\"\"\"\n\nc,900\n");
  const CsvTable t = ReadCsv(in, "runs.csv");
  ASSERT_EQ(t.header, (std::vector<std::string>{"label", "L_mm", "note"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0].row, 2);
  EXPECT_EQ(t.rows[0].cells[0], "a, b");
  EXPECT_EQ(t.rows[0].cells[2], "say \"hi\"");
  EXPECT_TRUE(t.rows[0].error.empty());
  EXPECT_EQ(t.rows[1].row, 3);  // the blank line is skipped, not counted as a record
  EXPECT_EQ(t.rows[1].error, "has 2 fields, the header has 3");
  EXPECT_EQ(t.Column("L_mm"), 1);
  EXPECT_EQ(t.Column("D_mm"), -1);
  EXPECT_EQ(CellContext(t, 3, "L_mm"), "runs.csv, row 3, column L_mm");
}

TEST(CsvTable, RefusesEmptyInputDuplicateAndEmptyHeaders) {
  const auto error = [](const std::string& text) {
    std::istringstream in(text);
    try {
      ReadCsv(in, "x.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error(""), "x.csv: is empty (expected a header row)");
  EXPECT_EQ(error("L,L\n1,2\n"), "x.csv: row 1 (header): duplicate column 'L'");
  EXPECT_EQ(error("L,,D\n"), "x.csv: row 1 (header), column 2: empty column name");
  EXPECT_NE(error("L,D\n\"1,2\n").find("malformed CSV"), std::string::npos);
  EXPECT_EQ(error("no-such-file"), "accepted");  // a one-column header is valid
}

FieldSource MapSource(const std::map<std::string, std::string>& fields) {
  FieldSource s;
  s.lookup = [fields](const std::string& name) -> std::optional<FieldSource::Field> {
    auto it = fields.find(name);
    if (it == fields.end()) return std::nullopt;
    return FieldSource::Field{it->second, ""};
  };
  s.context = [](const std::string& name) { return "--" + name; };
  return s;
}

std::string ConfigError(const std::map<std::string, std::string>& fields) {
  try {
    ParseConfiguration(MapSource(fields));
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(Configuration, ParsesTheLabSpheroidFromCrossbarMeasurements) {
  const Configuration c = ParseConfiguration(MapSource({{"body", "spheroid"},
                                                        {"a", "1.25in"},
                                                        {"b", "2in"},
                                                        {"L", "1165mm"},
                                                        {"H", "300mm"},
                                                        {"D", "120mm"},
                                                        {"u_D", "0.5mm"},
                                                        {"rod_diameter", "8mm"}}));
  EXPECT_EQ(c.body_kind, BodyKind::kSpheroid);
  EXPECT_DOUBLE_EQ(c.across.value, 0.03175);
  EXPECT_DOUBLE_EQ(c.along.value, 0.0508);
  EXPECT_TRUE(c.from_apparatus);
  EXPECT_DOUBLE_EQ(c.D.u, 0.0005);
  EXPECT_DOUBLE_EQ(c.rod_radius.value, 0.004);
  EXPECT_TRUE(c.HasUncertainty());
  EXPECT_DOUBLE_EQ(*c.CrossbarDistance(), 1.165);
  EXPECT_DOUBLE_EQ(c.MakeRails().tan_theta, 0.3 / 1.165);
}

TEST(Configuration, NamesTheFieldAndTheRuleForBadInput) {
  const std::map<std::string, std::string> ok = {
      {"body", "sphere"}, {"R", "12.7mm"}, {"L", "1165mm"}, {"H", "300mm"}, {"D", "100mm"}};
  EXPECT_EQ(ConfigError(ok), "accepted");
  auto with = [&](const std::string& k, const std::string& v) {
    auto m = ok;
    m[k] = v;
    return m;
  };
  auto without = [&](const std::string& k) {
    auto m = ok;
    m.erase(k);
    return m;
  };
  EXPECT_EQ(ConfigError(with("D", "-3mm")), "--D: must be > 0 (got -0.0030000000000000001)");
  EXPECT_EQ(ConfigError(with("R", "0mm")), "--R: must be > 0 (got 0)");
  EXPECT_EQ(ConfigError(with("body", "cube")),
            "--body: unknown body 'cube' (accepted: sphere, spheroid, double-cone)");
  EXPECT_EQ(ConfigError(without("D")), "--D: is missing (rail separation at the crossbar)");
  EXPECT_EQ(ConfigError(without("body")), "--body: is missing (sphere, spheroid or double-cone)");
  EXPECT_EQ(ConfigError(with("a", "3mm")), "--a: does not apply to a sphere (give R)");
  EXPECT_EQ(ConfigError(with("theta", "3deg")),
            "--theta: give either the crossbar measurements L, H, D or the angles theta, alpha, not both");
  EXPECT_EQ(ConfigError(with("u_D", "-1mm")), "--u_D: must be >= 0");
  EXPECT_EQ(ConfigError(with("L_convention", "diagonal")),
            "--L_convention: must be 'horizontal' or 'along-rail' (got 'diagonal')");
  EXPECT_EQ(ConfigError(with("L_convention", "along-rail")), "accepted");
  auto along_rail = with("L", "301mm");
  along_rail["L_convention"] = "along-rail";
  EXPECT_EQ(ConfigError(with("L", "301mm")), "accepted");  // horizontal: any L > 0 will do
  EXPECT_EQ(ConfigError(along_rail),
            "--L: measured along a rail must exceed sqrt(H^2 + D^2/4) = 0.30413812651491096 m "
            "(got 0.30099999999999999 m)");
  EXPECT_EQ(ConfigError(with("rod_diameter", "-2mm")),
            "--rod_diameter: must be a finite number >= 0 (got -0.001)");
  // A double cone whose rails open faster than its flanks cannot rest on both rails.
  EXPECT_NE(ConfigError({{"body", "double-cone"}, {"R", "50mm"}, {"h", "10mm"},
                         {"theta", "1deg"}, {"alpha", "120deg"}})
                .find("--body: the double cone cannot rest on both rails"),
            std::string::npos);
}

TEST(AtomicFile, ReplacesContentAndLeavesNoTemporary) {
  const auto dir = std::filesystem::temp_directory_path() / "uphill_atomic_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "out.txt").string();
  WriteFileAtomically(path, "first");
  WriteFileAtomically(path, "second\n");
  std::ifstream in(path);
  std::string content((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(content, "second\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
  EXPECT_THROW(WriteFileAtomically((dir / "missing" / "x.txt").string(), "x"), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// Regression tests for what fuzzing the readers found (tests/fuzz, scripts/fuzz.sh).

TEST(FuzzRegression, QuantityThatOverflowsInSIIsRefused) {
  // Found by fuzz_units: "1e307 km" is a finite number but 1e310 m, which must be refused, not
  // returned as +inf.
  const auto error = [](const std::string& text, Dimension dimension) {
    try {
      ParseQuantity(text, dimension, "--L");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("1e307 km", Dimension::kLength), "--L: '1e307 km' is out of the range of a double");
  EXPECT_EQ(error("-1e306km", Dimension::kLength), "--L: '-1e306km' is out of the range of a double");
  EXPECT_DOUBLE_EQ(ParseQuantity("-1e308in", Dimension::kLength, "--L"), -1e308 * 0.0254);  // shrinks
  EXPECT_DOUBLE_EQ(ParseQuantity("1e300 km", Dimension::kLength, "--L"), 1e303);
  // One sign only: "+-5 mm" is not -5 mm.
  EXPECT_EQ(error("+-5 mm", Dimension::kLength), "--L: '+-5 mm' is not a number");
  EXPECT_EQ(error("++5", Dimension::kDimensionless), "--L: '++5' is not a number");
  EXPECT_DOUBLE_EQ(ParseQuantity("+5 mm", Dimension::kLength, "--L"), 0.005);
}

TEST(FuzzRegression, CsvCellsThatAreNotUtf8AreRefusedPerRow) {
  // fuzz_csv_convert: a label in Latin-1 (a spreadsheet export) reached the JSON output of
  // `uphill convert --batch --json`, where nlohmann::json threw type_error 316 (exit 1, "internal
  // error"). Now the row is refused with its column and the other rows are kept.
  std::istringstream in("label,body,R_mm\ncaf\xE9,sphere,12.7\n"
                        "ok \xC2\xB5m \xE2\x82\xAC \xF0\x9F\x98\x80,sphere,1\n"
                        "\xC0\xAF,sphere,1\n\xED\xA0\x80,sphere,1\nx,sphere,\xE2\x82\n");
  const CsvTable t = ReadCsv(in, "runs.csv");
  ASSERT_EQ(t.rows.size(), 5u);
  EXPECT_EQ(t.rows[0].error, "column label: is not valid UTF-8 (save the file as UTF-8)");
  EXPECT_EQ(t.rows[1].error, "");  // well-formed 2-, 3- and 4-byte sequences
  EXPECT_EQ(t.rows[2].error, "column label: is not valid UTF-8 (save the file as UTF-8)");  // overlong
  EXPECT_EQ(t.rows[3].error, "column label: is not valid UTF-8 (save the file as UTF-8)");  // surrogate
  EXPECT_EQ(t.rows[4].error, "column R_mm: is not valid UTF-8 (save the file as UTF-8)");  // truncated
  std::istringstream header("L,\xFF\n1,2\n");
  try {
    ReadCsv(header, "x.csv");
    ADD_FAILURE() << "accepted a header that is not UTF-8";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "x.csv: row 1 (header), column 2: is not valid UTF-8 (save the file as UTF-8)");
  }
}

}  // namespace
}  // namespace uphill::testing
