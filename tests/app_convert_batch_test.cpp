// app::ConvertBatch (src/app/convert_batch.hpp): rows that differ only in their numbers take a
// short path (the first row's configuration with the numbers replaced; with BatchDetail::kSummary
// evaluated in blocks by the batch kernels); they must give exactly what parsing every row in
// full gives. Truth: the full path (ParseConfiguration and Convert per row, forced here by a label
// column, which the short path does not take), on the same rows, valid and invalid ones alike;
// and the row order and errors of the input.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <sstream>

#include "app/convert_batch.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

FieldSource Flags(const std::map<std::string, std::string>& flags = {{"body", "spheroid"}, {"a", "15.875mm"},
                                                                      {"b", "25.4mm"}}) {
  FieldSource s;
  s.lookup = [flags](const std::string& name) -> std::optional<FieldSource::Field> {
    const auto it = flags.find(name);
    if (it == flags.end()) return std::nullopt;
    return FieldSource::Field{it->second, ""};
  };
  s.context = [](const std::string& name) { return "--" + name; };
  return s;
}

// Every row's summary (kSummary) or error, as text holding each double's exact bits.
std::vector<std::string> Summaries(const std::string& csv, const FieldSource& flags, const ConversionOptions& options,
                                   BatchDetail detail) {
  std::istringstream in(csv);
  std::vector<std::string> out;
  const auto bits = [](double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    return std::to_string(u);
  };
  const auto maybe = [&](const std::optional<double>& v) { return v ? bits(*v) : std::string("-"); };
  ConvertBatch(
      in, "b.csv", flags, options, [](const BatchHeader&) {},
      [&](const ConvertedRow& row) {
        EXPECT_EQ(row.result.has_value(), detail == BatchDetail::kFull && row.error.empty());
        EXPECT_EQ(row.summary.has_value(), detail == BatchDetail::kSummary && row.error.empty());
        std::string text = std::to_string(row.row) + " ";
        if (!row.error.empty()) {
          out.push_back(text + "error: " + row.error);
          return;
        }
        const ConversionSummary v = row.summary ? *row.summary : Summarize(*row.result);
        text += std::to_string(static_cast<int>(v.body)) + " " + bits(v.theta) + " " + bits(v.alpha) + " " +
                bits(v.phi) + " " + maybe(v.x_eq) + " " + bits(v.x_max) + " " + maybe(v.u_x_eq) + " " +
                maybe(v.u_mc_x_eq) + " " + (v.rest ? bits(v.rest->low) + " " + bits(v.rest->high) : "-") + " " +
                maybe(v.theta0) + " " + std::to_string(v.rolls_up) + std::to_string(v.x_eq_beyond_crossbar) +
                std::to_string(v.uncertainty_disagrees);
        out.push_back(text);
      },
      detail);
  return out;
}

// Rows of `header` (numeric columns) from `cell(i, j)`, and the same rows behind an empty label
// column (which sends every row through the full path).
std::pair<std::string, std::string> Files(const std::string& header, int rows,
                                          const std::function<std::string(int, int)>& cell, int columns) {
  std::string numeric = header + "\n", labelled = "label," + header + "\n";
  for (int i = 0; i < rows; ++i) {
    std::string line;
    for (int j = 0; j < columns; ++j) line += (j ? "," : "") + cell(i, j);
    numeric += line + "\n";
    labelled += "," + line + "\n";
  }
  return {numeric, labelled};
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

// The block path (kSummary) against the full path, bit for bit, over more rows than one block,
// with rows the full path must take (odd cells, values outside the model's domain) scattered
// among them so that blocks are cut short and rows must keep their order.
TEST(ConvertBatch, SummaryBlocksGiveExactlyTheFullPathsNumbers) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> L(500, 2000), H(0.5, 500), D(20, 250);
  const std::vector<std::string> odd = {"-5", "0", "", "abc", "1e999", "+7.5", " 12 ", "1e-320", "-0"};
  const int rows = static_cast<int>(kSummaryBlock) + 1500;
  const auto cell = [&](int i, int j) {
    if (i % 97 == 13 && j == i % 3) return odd[static_cast<std::size_t>(i / 97) % odd.size()];
    std::ostringstream text;
    text.precision(17);
    text << (j == 0 ? L(rng) : j == 1 ? H(rng) : D(rng));
    return text.str();
  };
  const auto [numeric, labelled] = Files("L_mm,H_mm,D_mm", rows, cell, 3);
  const std::vector<std::string> block = Summaries(numeric, Flags(), {}, BatchDetail::kSummary);
  const std::vector<std::string> full = Summaries(labelled, Flags(), {}, BatchDetail::kFull);
  ASSERT_EQ(block.size(), static_cast<std::size_t>(rows));
  EXPECT_EQ(block, full);
  std::size_t errors = 0, beyond = 0;
  for (const std::string& r : block) {
    errors += r.find(" error: ") != std::string::npos;
    beyond += r.size() > 3 && r.compare(r.size() - 3, 3, "110") == 0;
  }
  EXPECT_GE(errors, 30u);  // the odd cells were refused, by row
  EXPECT_GE(beyond, 100u);  // and the note occurs: X beyond the crossbar (D < 2b, H not small)
}

// The other shapes the block path covers, and one it leaves to the full path: a sphere on rods
// (the enlarged sphere), angles instead of L, H, D, L along a rail (with rows where L is too short),
// a spheroid on rods; and with --mu every row takes the full path.
TEST(ConvertBatch, SummaryBlocksCoverSpheresOnRodsAnglesAndAlongRailL) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  const auto number = [&](double lo, double hi) {
    std::ostringstream text;
    text.precision(17);
    text << lo + (hi - lo) * u(rng);
    return text.str();
  };
  struct Case {
    std::string header;
    std::map<std::string, std::string> flags;
    std::function<std::string(int, int)> cell;
    int columns;
  };
  const std::vector<Case> cases = {
      {"R_mm,rod_diameter_mm,L_mm,H_mm,D_mm", {{"body", "sphere"}},
       [&](int i, int j) {
         if (i % 50 == 7 && j == 1) return std::string("-2");
         return j == 0 ? number(5, 30) : j == 1 ? number(1, 8) : j == 2 ? number(500, 2000) : j == 3 ? number(1, 400) : number(20, 250);
       },
       5},
      {"theta_deg,alpha_deg", {{"body", "spheroid"}, {"a", "15.875mm"}, {"b", "25.4mm"}},
       [&](int i, int j) {
         if (i % 40 == 3) return std::string(j == 0 ? "90" : "10");
         return j == 0 ? number(0.01, 89.9) : number(0.01, 179.9);
       },
       2},
      {"L_mm,H_mm,D_mm", {{"body", "spheroid"}, {"a", "15.875mm"}, {"b", "25.4mm"}, {"L_convention", "along-rail"}},
       [&](int i, int j) {
         if (i % 30 == 5 && j == 0) return std::string("150");  // shorter than hypot(H, D/2)
         return j == 0 ? number(600, 2000) : j == 1 ? number(1, 400) : number(20, 250);
       },
       3},
      {"a_mm,b_mm,rod_diameter_mm,L_mm,H_mm,D_mm", {{"body", "spheroid"}},
       [&](int i, int j) {
         (void)i;
         return j == 0 ? number(10, 20) : j == 1 ? number(20, 30) : j == 2 ? number(2, 6) : j == 3 ? number(800, 1500) : j == 4 ? number(50, 300) : number(40, 200);
       },
       6},
  };
  for (const Case& c : cases) {
    const auto [numeric, labelled] = Files(c.header, 300, c.cell, c.columns);
    const std::vector<std::string> block = Summaries(numeric, Flags(c.flags), {}, BatchDetail::kSummary);
    EXPECT_EQ(block, Summaries(labelled, Flags(c.flags), {}, BatchDetail::kFull)) << c.header;
    EXPECT_EQ(block.size(), 300u);
  }
  ConversionOptions with_mu;
  with_mu.mu = 0.01;
  const auto [numeric, labelled] = Files("L_mm,H_mm,D_mm", 50, [&](int, int j) { return number(100 + 400 * (j == 0), 600); }, 3);
  const std::vector<std::string> rest = Summaries(numeric, Flags(), with_mu, BatchDetail::kSummary);
  EXPECT_EQ(rest, Summaries(labelled, Flags(), with_mu, BatchDetail::kFull));
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
