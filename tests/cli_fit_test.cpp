// `uphill fit` and `uphill report` end to end: certified data through the stable --xy JSON
// interface, the hard cases with their exit codes, the sample experiments, and the report folder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "file_test_support.hpp"

namespace uphill::testing {
namespace {

using nlohmann::json;
using testing::RunUphill;

const std::string kSource = UPHILL_SOURCE_DIR;

// Columns of a whitespace data file in tests/data (comment lines start with '#').
std::vector<std::vector<double>> ReadDat(const std::string& name) {
  std::ifstream in(kSource + "/tests/data/" + name);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::vector<double> row;
    for (double v; s >> v;) row.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

std::string Csv(const std::vector<std::vector<double>>& rows, const std::string& header) {
  std::ostringstream out;
  out.precision(17);
  out << header << "\n";
  for (const auto& r : rows) {
    for (size_t i = 0; i < r.size(); ++i) out << (i ? "," : "") << r[i];
    out << "\n";
  }
  return out.str();
}

void ExpectDigits(double actual, double expected, double digits, const std::string& what) {
  EXPECT_LE(std::abs(actual - expected), std::abs(expected) * std::pow(10.0, -digits)) << what;
}

TEST(FitCli, NistNorrisCertifiedValuesThroughTheJsonInterface) {
  std::vector<std::vector<double>> xy;
  for (const auto& r : ReadDat("nist_norris.dat")) xy.push_back({r[1], r[0]});  // file is y x
  ASSERT_EQ(xy.size(), 36u);
  const auto r = RunUphill("fit --xy - --method ols --json", Csv(xy, "X,Y"));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ExpectDigits(j.at("slope"), 1.00211681802045, 12, "B1");
  ExpectDigits(j.at("intercept"), -0.262323073774029, 12, "B0");
  ExpectDigits(j.at("u_slope"), 0.429796848199937E-03, 12, "sd(B1)");
  ExpectDigits(j.at("u_intercept"), 0.232818234301152, 12, "sd(B0)");
  ExpectDigits(j.at("chi2"), 26.6173985294224, 12, "RSS");
  EXPECT_EQ(j.at("dof"), 34);
  EXPECT_EQ(j.at("n"), 36);
  EXPECT_TRUE(j.at("p_value").is_null());  // OLS has no stated uncertainties
}

TEST(FitCli, PearsonYorkPublishedSolution) {
  std::vector<std::vector<double>> rows;
  for (const auto& r : ReadDat("pearson_york.dat")) rows.push_back({r[0], r[2], 1 / std::sqrt(r[1]), 1 / std::sqrt(r[3])});
  ASSERT_EQ(rows.size(), 10u);
  const auto r = RunUphill("fit --xy - --method york --json", Csv(rows, "X,Y,uX,uY"));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ExpectDigits(j.at("slope"), -0.480533407, 8.5, "slope");
  ExpectDigits(j.at("intercept"), 5.479910224, 8.5, "intercept");
  ExpectDigits(j.at("u_slope"), 0.0579850090, 8.5, "sigma(slope), unscaled");
  ExpectDigits(j.at("u_intercept"), 0.294970735, 8.5, "sigma(intercept), unscaled");
  ExpectDigits(j.at("chi2").get<double>() / j.at("dof").get<double>(), 1.483294149, 8.5, "MSWD");
}

TEST(FitCli, HugeOffsetLosesNoDigits) {
  // X around 1e9 with a spread of 1: the slope must equal that of the same data at X around 0.
  // X = 2^30 + i/8 is exact in binary64, so both data sets hold the same differences exactly.
  std::ostringstream near, far;
  near.precision(17);
  far.precision(17);
  near << "X,Y\n";
  far << "X,Y\n";
  for (int i = 0; i < 11; ++i) {
    const double x = i / 8.0, y = 2.5 * x + 0.3 * std::sin(7.0 * i);
    near << x << "," << y << "\n";
    far << 1073741824.0 + x << "," << y << "\n";
  }
  const json a = json::parse(RunUphill("fit --xy - --json", near.str()).out);
  const json b = json::parse(RunUphill("fit --xy - --json", far.str()).out);
  ExpectDigits(b.at("slope"), a.at("slope"), 13, "slope");
  ExpectDigits(b.at("u_slope"), a.at("u_slope"), 12, "u(slope)");
}

TEST(FitCli, HardCasesGiveClearErrorsOrNotes) {
  const auto none = RunUphill("fit --xy -", "X,Y\n");
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("uphill: "), std::string::npos);
  const auto one = RunUphill("fit --xy -", "X,Y\n1,2\n");
  EXPECT_EQ(one.status, 2) << one.err;
  const auto equal = RunUphill("fit --xy -", "X,Y\n3,1\n3,2\n3,4\n");
  EXPECT_EQ(equal.status, 2);
  EXPECT_NE(equal.err.find("X"), std::string::npos) << equal.err;
  const auto no_u = RunUphill("fit --xy - --method wls", "X,Y\n1,2\n2,3\n3,5\n");
  EXPECT_EQ(no_u.status, 2);
  const auto zero_u = RunUphill("fit --xy - --method york", "X,Y,uX,uY\n1,2,0.1,0\n2,3,0.1,0.1\n3,5,0.1,0.1\n");
  EXPECT_EQ(zero_u.status, 2);
  const auto two = RunUphill("fit --xy - --json", "X,Y\n1,2\n3,6\n");
  ASSERT_EQ(two.status, 0) << two.err;
  const json j = json::parse(two.out);
  EXPECT_DOUBLE_EQ(j.at("slope"), 2.0);
  EXPECT_DOUBLE_EQ(j.at("intercept"), 0.0);
  EXPECT_EQ(j.at("dof"), 0);
  EXPECT_TRUE(j.at("exact"));
  EXPECT_TRUE(j.at("u_slope").is_null());  // no scatter, no uncertainty
  EXPECT_FALSE(j.at("notes").empty());
  // Found by fuzzing: an uncertainty near the largest double made Ceres' residuals overflow.
  const auto huge = RunUphill("fit --xy - --method york",
                              "X,Y,uX,uY\n0.3,0.59,0.001,2\n0.3,0.59,0.001,0.002\n0.4,0.8,0.001e+308,0.002\n");
  EXPECT_EQ(huge.status, 2);
  EXPECT_EQ(huge.err, "uphill: <stdin>, row 4, column uX: must lie in [1e-100, 1e100] (got "
                      "9.9999999999999994e+304): its square or inverse square would overflow a double\n");
  const auto method = RunUphill("fit --xy - --method odr", "X,Y\n1,2\n2,3\n3,5\n");
  EXPECT_EQ(method.status, 2);
  EXPECT_EQ(method.err, "uphill: --method: must be ols, wls, york or robust (got 'odr')\n");
}

TEST(FitCli, BadRowsAreNamedAndTheRestFitted) {
  const auto r = RunUphill("fit --xy - --json", "X,Y\n1,2\n2,abc\n3,4\n4,5\n");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "uphill: <stdin>, row 3, column Y: 'abc' is not a number (row left out)\n");
  EXPECT_EQ(json::parse(r.out).at("n"), 3);
  const auto unknown = RunUphill("fit --xy -", "X,Y,sigma\n1,2,3\n");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(unknown.err,
            "uphill: <stdin>, row 1, column sigma: unknown column (expected X, Y and optionally uX, uY)\n");
}

TEST(FitCli, SampleExperimentRecoversTheFrictionItWasMadeWith) {
  // data/series1-fixed-D was generated with mu = 0.05 (tools/make_samples).
  const auto r = RunUphill("fit " + kSource + "/data/series1-fixed-D --json --mc-trials 1000");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("format"), "uphill-fit/1");
  EXPECT_EQ(j.at("rows").size(), 21u);
  const json& friction = j.at("fits").at("friction");
  const double mu = friction.at("parameters")[0].at("value"), u = friction.at("parameters")[0].at("se_unscaled");
  EXPECT_NEAR(mu, 0.05, 3 * u);
  EXPECT_LT(u, 0.02);
  for (const char* method : {"ols", "wls", "york", "robust"}) {
    EXPECT_NEAR(j.at("fits").at(method).at("slope").get<double>(), 1.0, 0.03) << method;
  }
}

TEST(FitCli, ReportFolderIsCompleteSelfContainedAndEscaped) {
  namespace fs = std::filesystem;
  const fs::path exp = fs::temp_directory_path() / "uphill_report_exp";
  const fs::path out = fs::temp_directory_path() / "uphill_report_out";
  fs::remove_all(exp);
  fs::remove_all(out);
  fs::create_directories(exp);
  fs::copy_file(kSource + "/data/series2-fixed-L/measurements.csv", exp / "measurements.csv");
  json meta = json::parse(std::ifstream(kSource + "/data/series2-fixed-L/experiment.json"));
  meta["notes"] = "<script>alert('x')</script> & friends";
  std::ofstream(exp / "experiment.json") << meta.dump();
  const auto r = RunUphill("report " + exp.string() + " -o " + out.string() + " --mc-trials 1000");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"report.html", "report.md", "fit.json", "fit_y_vs_x.svg", "fit_y_vs_x.png", "fit_y_vs_x.gp",
                        "fit_y_vs_x.dat", "fit_offset.svg", "fit_residuals.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_NE(entry.path().filename().string()[0], '.') << "left-over temporary " << entry.path();
  std::stringstream html;
  html << std::ifstream(out / "report.html").rdbuf();
  EXPECT_EQ(html.str().find("<script"), std::string::npos);
  EXPECT_NE(html.str().find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; friends"), std::string::npos);
  EXPECT_EQ(html.str().find("http://"), std::string::npos);  // opens offline: nothing external
  EXPECT_EQ(html.str().find("https://"), std::string::npos);
  EXPECT_NE(html.str().find("data:image/svg+xml;base64,"), std::string::npos);
  const json fit = json::parse(std::ifstream(out / "fit.json"));
  EXPECT_EQ(fit.at("rows").size(), 24u);
  // The gnuplot script kept beside the figure redraws it.
  const std::string redraw = "cd " + out.string() + " && gnuplot fit_y_vs_x.gp";
  EXPECT_EQ(std::system(redraw.c_str()), 0);
  fs::remove_all(exp);
  fs::remove_all(out);
}

TEST(FitCli, ReportIntoARelativeFolderThatDoesNotExistYet) {
  // The Quick start's form: `uphill report data/series1-fixed-D -o out/series1-fixed-D`.
  namespace fs = std::filesystem;
  const fs::path work = fs::temp_directory_path() / "uphill_report_relative";
  fs::remove_all(work);
  fs::create_directories(work);
  const std::string command = "cd " + work.string() + " && " + UPHILL_PROGRAM + " report " + kSource +
                              "/data/series1-fixed-D -o out/nested/series1 --mc-trials 1000 > /dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0);
  EXPECT_TRUE(fs::exists(work / "out/nested/series1/report.html"));
  EXPECT_TRUE(fs::exists(work / "out/nested/series1/fit_y_vs_x.png"));
  fs::remove_all(work);
}

TEST(FitCli, ReportOfABadExperimentNamesTheProblem) {
  const auto r = RunUphill("report /nonexistent/exp -o /tmp/uphill_never_written");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "uphill: /nonexistent/exp: is not an experiment folder\n");
  EXPECT_FALSE(std::filesystem::exists("/tmp/uphill_never_written"));
}

// Guards: `uphill report EXP -o EXP` replaced the camera file when experiment.json named it
// "fit.json", and a scene named like a figure; every later `fit` then failed. Truth: the inputs'
// bytes before and after, and docs/exit-codes.md (status 2, one line naming the output and the
// input). The inputs are compared by identity: a hard link under another name is refused too.
TEST(FitCli, ReportNeverReplacesAnInputOfTheExperiment) {
  namespace fs = std::filesystem;
  const fs::path exp = FreshFolder("report-inputs");
  std::ofstream(exp / "experiment.json") << R"({"format": "uphill-experiment/2",
    "body": {"type": "sphere", "R": "25.4 mm"}, "apparatus": {"L": "1000 mm", "H": "100 mm"},
    "uncertainties": {"D": "0.2 mm", "Y": "0.5 mm"},
    "camera": "fit.json", "scenes": {"main": "fit_y_vs_x.svg"}})";
  std::ofstream(exp / "measurements.csv") << "trial,D_mm,Y_mm\na,150,340\nb,160,330\nc,140,350\n";
  std::ofstream(exp / "fit.json") << "{\"camera\": true}\n";
  std::ofstream(exp / "fit_y_vs_x.svg") << "{\"scene\": true}\n";
  const auto unchanged = [&] {
    EXPECT_EQ(ReadBytes(exp / "fit.json"), "{\"camera\": true}\n");
    EXPECT_EQ(ReadBytes(exp / "fit_y_vs_x.svg"), "{\"scene\": true}\n");
    EXPECT_FALSE(fs::exists(exp / "report.html"));
  };
  auto r = RunUphill("report " + exp.string() + " -o " + exp.string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("camera file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((exp / "fit.json").string()), std::string::npos) << r.err;
  unchanged();
  // The same file under another name: a report folder whose fit.json is a hard link to the camera.
  const fs::path out = exp / "out";
  fs::create_directories(out);
  fs::create_hard_link(exp / "fit.json", out / "fit.json");
  r = RunUphill("report " + exp.string() + " -o " + out.string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("camera file"), std::string::npos) << r.err;
  unchanged();
  // The scene file alone in the way (the camera moved elsewhere).
  fs::remove(out / "fit.json");
  fs::create_hard_link(exp / "fit_y_vs_x.svg", out / "fit_y_vs_x.svg");
  r = RunUphill("report " + exp.string() + " -o " + out.string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("scene file 'main'"), std::string::npos) << r.err;
  unchanged();
  // Nor into the folder's video cache.
  fs::create_directories(exp / ".uphill-cache" / "video");
  r = RunUphill("report " + exp.string() + " -o " + (exp / ".uphill-cache" / "video").string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("video cache"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(exp / ".uphill-cache" / "video" / "report.html"));
  // And `fit` still reads the experiment.
  EXPECT_EQ(RunUphill("fit " + exp.string() + " --mc-trials 1000").status, 0);
  fs::remove_all(exp);
}

}  // namespace
}  // namespace uphill::testing
