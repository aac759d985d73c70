// app::ConvertBatch (src/app/convert_batch.hpp): rows that differ only in their numbers take a
// short path (the first row's configuration with the numbers replaced); they must give exactly
// what parsing every row in full gives. Truth: the full path (ParseConfiguration per row,
// forced here by a label column, which the short path does not take), on the same rows, valid
// and invalid ones alike; and the row order and errors of the input.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "app/convert_batch.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

FieldSource Flags() {
  FieldSource s;
  s.lookup = [](const std::string& name) -> std::optional<FieldSource::Field> {
    if (name == "body") return FieldSource::Field{"spheroid", ""};
    if (name == "a") return FieldSource::Field{"15.875mm", ""};
    if (name == "b") return FieldSource::Field{"25.4mm", ""};
    return std::nullopt;
  };
  s.context = [](const std::string& name) { return "--" + name; };
  return s;
}

std::vector<std::string> ConvertAll(const std::string& csv) {
  std::istringstream in(csv);
  std::vector<std::string> out;
  ConversionOptions options;
  options.mu = 0.02;
  options.propagation.trials = 1000;  // seeded: the same draws on both paths
  ConvertBatch(in, "b.csv", Flags(), options, [](const BatchHeader&) {},
               [&](const ConvertedRow& row) {
                 out.push_back(std::to_string(row.row) + " " +
                               (row.result ? ToJson(*row.result).dump() : "error: " + row.error));
               });
  return out;
}

TEST(ConvertBatch, NumericRowsGiveExactlyTheFullParsesResults) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> L(500, 2000), H(50, 500), D(20, 250), u(0.1, 2);
  std::string numeric = "L_mm,H_mm,D_mm,u_D_mm,note\n", labelled = "label,L_mm,H_mm,D_mm,u_D_mm,note\n";
  const std::vector<std::string> odd = {"-5", "0", "", "abc", "+-3", "1e999", "+7.5", " 12 "};
  for (int i = 0; i < 60; ++i) {
    std::ostringstream row;
    row.precision(17);
    row << L(rng) << "," << H(rng) << ",";
    if (i % 7 == 3) row << odd[static_cast<std::size_t>(i / 7) % odd.size()];
    else row << D(rng);
    row << "," << (i % 11 == 5 ? std::string("-0.5") : std::to_string(u(rng))) << ",n" << i << "\n";
    numeric += row.str();
    labelled += "," + row.str();
  }
  const std::vector<std::string> fast = ConvertAll(numeric), full = ConvertAll(labelled);
  ASSERT_EQ(fast.size(), 60u);
  EXPECT_EQ(fast, full);
  std::size_t errors = 0;
  for (const std::string& r : fast) errors += r.find(" error: ") != std::string::npos;
  EXPECT_GE(errors, 10u);  // the odd cells and negative uncertainties were refused, by row
}

TEST(ConvertBatch, RowsComeInInputOrderAndAHeaderOnlyFileIsRefused) {
  const std::vector<std::string> rows = ConvertAll("L_mm,H_mm,D_mm\n1165,300,100\n1165,300,-1\n1165,300,120\n");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].substr(0, 2), "2 ");
  EXPECT_EQ(rows[1], "3 error: b.csv, row 3, column D_mm: must be > 0 (got -0.001)");
  EXPECT_EQ(rows[2].substr(0, 2), "4 ");
  EXPECT_THROW(ConvertAll("L_mm,H_mm,D_mm\n"), InputError);
}

}  // namespace
}  // namespace uphill::testing
