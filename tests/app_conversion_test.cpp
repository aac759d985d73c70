// The conversion use case (src/app/conversion.hpp, convert_batch.hpp): one setting and a batch,
// a bad row kept with its error while the others go on, the flags' defaults filling absent
// columns, and the JSON of a result. Truth: lab_exp2_L1165_H300_D100 of the 60-digit reference
// (tests/data/physics_reference.json).
#include <gtest/gtest.h>

#include <map>
#include <sstream>

#include "app/convert_batch.hpp"
#include "model/input_error.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

const nlohmann::json& Lab() { return ReferenceCase("lab_exp2_L1165_H300_D100").at("outputs"); }

// Fields the table lacks, as command-line defaults would give them (nothing: an empty map).
FieldSource Defaults(std::map<std::string, std::string> values) {
  FieldSource s;
  s.lookup = [values](const std::string& name) -> std::optional<FieldSource::Field> {
    const auto it = values.find(name);
    if (it == values.end()) return std::nullopt;
    return FieldSource::Field{it->second, ""};
  };
  s.context = [](const std::string& name) { return "--" + name; };
  return s;
}
const std::map<std::string, std::string> kLabSpheroid = {{"body", "spheroid"}, {"a", "15.875mm"}, {"b", "25.4mm"}};

std::vector<ConvertedRow> Batch(const std::string& text, const FieldSource& defaults, const ConversionOptions& o) {
  std::istringstream in(text);
  std::vector<ConvertedRow> rows;
  ConvertBatch(in, "batch.csv", defaults, o, [](const BatchHeader&) {}, [&](const ConvertedRow& r) { rows.push_back(r); });
  return rows;
}

TEST(Conversion, OneSettingMatchesTheReferenceAndItsJsonKeepsEveryNumber) {
  FieldSource flags = Defaults({{"body", "spheroid"}, {"a", "15.875mm"}, {"b", "25.4mm"}, {"L", "1165mm"},
                                {"H", "300mm"}, {"D", "100mm"}});
  ConversionOptions o;
  o.mu = 0.01;
  const ConversionResult r = Convert(ParseConfiguration(flags), o);
  EXPECT_REF(*r.scene.x_eq(), Lab().at("x_eq"), 4.0);
  EXPECT_REF(r.rest->high, Lab().at("rest")[1].at("x_rest"), 4.0);
  EXPECT_FALSE(r.verdict.empty());
  // Round trip through the JSON text: the numbers come back to the bit.
  const nlohmann::json j = nlohmann::json::parse(ToJson(r).dump());
  EXPECT_EQ(j.at("x_eq").get<double>(), *r.scene.x_eq());
  EXPECT_EQ(j.at("x_max").get<double>(), r.scene.x_max());
  EXPECT_EQ(j.at("x_rest").get<double>(), r.rest->high);
  EXPECT_EQ(j.at("verdict").size(), r.verdict.size());
}

TEST(ConvertBatch, EveryRowIsConvertedAndABadRowKeepsItsError) {
  ConversionOptions o;
  o.mu = 0.01;
  const std::vector<ConvertedRow> rows =
      Batch("label,L_mm,H_mm,D_mm\nlab,1165,300,100\nbad,1165,300,-5\nagain,1165,300,100\n", Defaults(kLabSpheroid), o);
  ASSERT_EQ(rows.size(), 3u);
  for (int i : {0, 2}) {
    SCOPED_TRACE(i);
    ASSERT_TRUE(rows[i].result) << rows[i].error;
    EXPECT_EQ(rows[i].row, i + 2);  // spreadsheet rows: the header is row 1
    EXPECT_REF(*rows[i].result->scene.x_eq(), Lab().at("x_eq"), 4.0);
    EXPECT_REF(rows[i].result->rest->high, Lab().at("rest")[1].at("x_rest"), 4.0);
  }
  EXPECT_EQ(rows[0].result->configuration.label, "lab");
  EXPECT_FALSE(rows[1].result);
  EXPECT_EQ(rows[1].row, 3);
  EXPECT_EQ(rows[1].error.rfind("batch.csv, row 3, column D_mm: ", 0), 0u) << rows[1].error;
}

TEST(ConvertBatch, UnitsInCellsAndWithoutDefaultsEachRowNamesItsBody) {
  const std::vector<ConvertedRow> rows =
      Batch("body,a,b,L,H,D\nspheroid,15.875mm,25.4mm,1.165m,30cm,100mm\n,,,1165mm,300mm,100mm\n", Defaults({}), {});
  ASSERT_EQ(rows.size(), 2u);
  ASSERT_TRUE(rows[0].result) << rows[0].error;
  EXPECT_REF(*rows[0].result->scene.x_eq(), Lab().at("x_eq"), 4.0);
  EXPECT_FALSE(rows[1].result);
  EXPECT_NE(rows[1].error.find("batch.csv, row 3"), std::string::npos) << rows[1].error;
}

TEST(ConvertBatch, AHeaderWithoutRowsIsRefusedAsAWhole) {
  EXPECT_THROW(Batch("L_mm,H_mm,D_mm\n", Defaults(kLabSpheroid), {}), InputError);
}

}  // namespace
}  // namespace uphill::testing
