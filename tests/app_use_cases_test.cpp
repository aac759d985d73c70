// Two use cases of src/app called through all three front ends on the same input: the program
// (`uphill fit`), the page's HTTP API (POST /api/fit-xy, POST /api/report) and the Python module
// (uphill.fit_xy, uphill.analyse_experiment). Each must give the same numbers and the same error
// text, since each only translates arguments and results.
// Truth: for FitXy, NIST StRD's certified values of the Norris data set (tests/data/nist_norris.dat,
// its header cites them); for AnalyseExperimentFolder, agreement of the three fronts on the sample
// experiment data/series2-fixed-L (the analysis itself is tested against references elsewhere:
// report_fit_json_test, experiment_test).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "file_test_support.hpp"
#include "server_test_support.hpp"
#include "use_case_support.hpp"

namespace uphill::testing {
namespace {

// Norris as NIST gives it: columns y x.
struct Norris {
  std::vector<double> x, y;
};

Norris ReadNorris() {
  Norris n;
  std::ifstream in(std::string(UPHILL_TEST_DATA_DIR) + "/nist_norris.dat");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double y = 0, x = 0;
    fields >> y >> x;
    n.x.push_back(x);
    n.y.push_back(y);
  }
  return n;
}

// The keys of `uphill fit --xy --json` that carry the fit's numbers (docs/fit.md).
void ExpectSameFit(const json& a, const json& b, const std::string& front) {
  for (const char* key : {"slope", "intercept", "u_slope", "u_intercept", "chi2", "dof", "n"})
    EXPECT_EQ(a.at(key), b.at(key)) << front << ": " << key;
  EXPECT_EQ(a.at("rows"), b.at("rows")) << front;
  EXPECT_EQ(WithoutTimes(a), WithoutTimes(b)) << front << ": the whole document";
}

class FitXyUseCase : public ServerFixture {};

TEST_F(FitXyUseCase, NorrisGivesTheCertifiedLineThroughEveryFront) {
  const Norris norris = ReadNorris();
  ASSERT_EQ(norris.x.size(), 36u);
  fs::create_directories(dir_);
  std::ofstream csv(dir_ / "norris.csv");
  csv.precision(17);
  csv << "X,Y\n";
  for (std::size_t i = 0; i < norris.x.size(); ++i) csv << norris.x[i] << "," << norris.y[i] << "\n";
  csv.close();

  const CommandResult cli = RunUphill("fit --xy " + (dir_ / "norris.csv").string() + " --json");
  ASSERT_EQ(cli.status, 0) << cli.err;
  const json from_cli = json::parse(cli.out);

  const auto [status, from_http] = Send("POST", "/api/fit-xy", {{"method", "ols"}, {"x", norris.x}, {"y", norris.y}});
  ASSERT_EQ(status, 200) << from_http.dump();

  const json from_python = PythonJson(dir_, "import json, uphill\n"
                                            "xy = uphill.read_xy('" + (dir_ / "norris.csv").string() + "')\n"
                                            "print(json.dumps(uphill.fit_xy(xy['x'], xy['y']).to_json()))\n");
  // NIST's certified values (nist_norris.dat): the primary standard errors of OLS are the usual ones.
  const auto near = [](double value, double certified) { return std::abs(value - certified) <= 1e-9 * std::abs(certified); };
  EXPECT_TRUE(near(from_cli.at("slope").get<double>(), 1.00211681802045)) << from_cli.at("slope");
  EXPECT_TRUE(near(from_cli.at("intercept").get<double>(), -0.262323073774029)) << from_cli.at("intercept");
  EXPECT_TRUE(near(from_cli.at("u_slope").get<double>(), 0.429796848199937e-3)) << from_cli.at("u_slope");
  EXPECT_TRUE(near(from_cli.at("u_intercept").get<double>(), 0.232818234301152)) << from_cli.at("u_intercept");
  ExpectSameFit(from_cli, from_http, "HTTP");
  ExpectSameFit(from_cli, from_python, "Python");
}

TEST_F(FitXyUseCase, AnUnknownMethodIsRefusedInTheSameWords) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "xy.csv") << "X,Y\n1,2\n2,3\n3,5\n";
  const std::string rule = "must be ols, wls, york or robust (got 'lsq')";
  const CommandResult cli = RunUphill("fit --xy " + (dir_ / "xy.csv").string() + " --method lsq");
  EXPECT_EQ(cli.status, 2);
  EXPECT_EQ(cli.err, "uphill: --method: " + rule + "\n");
  const auto [status, http] = Send("POST", "/api/fit-xy", {{"method", "lsq"}, {"x", {1, 2, 3}}, {"y", {2, 3, 5}}});
  EXPECT_EQ(status, 422);
  EXPECT_EQ(http.value("error", ""), "method: " + rule);
  const json python = PythonJson(dir_, "import json, uphill\n"
                                       "try:\n"
                                       "    uphill.fit_xy([1.0, 2.0, 3.0], [2.0, 3.0, 5.0], method='lsq')\n"
                                       "except uphill.InputError as e:\n"
                                       "    print(json.dumps(str(e)))\n");
  EXPECT_EQ(python, "method: " + rule);
}

// The server's report analyses the folder it serves: a copy of the sample experiment, which the
// program and the module analyse too (the same path, so that fit.json's directory agrees).
class ExperimentFolderUseCase : public ServerFixture {
 protected:
  void SetUp() override {
    fs::create_directories(dir_);
    for (const char* file : {"experiment.json", "measurements.csv"})
      fs::copy_file(fs::path(UPHILL_SOURCE_DIR) / "data" / "series2-fixed-L" / file, dir_ / file);
    ServerFixture::SetUp();
  }
  // The server's report trials, given to the other fronts too.
  static constexpr int kTrials = 1000;
  void Configure(ServerOptions& options) override { options.report_mc_trials = kTrials; }
};

TEST_F(ExperimentFolderUseCase, TheSampleExperimentGivesTheSameAnalysisThroughEveryFront) {
  const std::string folder = dir_.string();
  const CommandResult cli = RunUphill("fit " + folder + " --json --mc-trials " + std::to_string(kTrials));
  ASSERT_EQ(cli.status, 0) << cli.err;
  const json from_cli = WithoutTimes(json::parse(cli.out));
  const json from_python =
      WithoutTimes(PythonJson(dir_, "import json, uphill\n"
                                            "a = uphill.analyse_experiment('" + folder + "', mc_trials=" +
                                                std::to_string(kTrials) + ")\n"
                                            "print(json.dumps(a.to_json()))\n"));
  const auto [status, answer] = Send("POST", "/api/report", json::object());
  ASSERT_EQ(status, 200) << answer.dump();
  const json from_http = WithoutTimes(json::parse(ReadBytes(dir_ / "report" / "fit.json")));

  ASSERT_FALSE(from_cli.at("rows").empty());
  EXPECT_EQ(from_cli.at("rows"), from_http.at("rows"));
  EXPECT_EQ(from_cli.at("fits"), from_http.at("fits"));
  EXPECT_EQ(from_cli, from_http) << "the whole of fit.json";
  EXPECT_EQ(from_cli, from_python) << "the whole of fit.json";
}

TEST_F(ExperimentFolderUseCase, AMissingFolderIsRefusedInTheSameWords) {
  const std::string missing = (dir_ / "no-such-experiment").string();
  const CommandResult cli = RunUphill("fit " + missing);
  EXPECT_EQ(cli.status, 2);
  const json python = PythonJson(dir_, "import json, uphill\n"
                                       "try:\n"
                                       "    uphill.analyse_experiment('" + missing + "')\n"
                                       "except uphill.InputError as e:\n"
                                       "    print(json.dumps(str(e)))\n");
  ASSERT_TRUE(python.is_string());
  EXPECT_EQ(cli.err, "uphill: " + python.get<std::string>() + "\n");
}

}  // namespace
}  // namespace uphill::testing
