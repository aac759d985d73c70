// A property test of the whole program (issue 11): every command run with random flags, most of
// them plausible and some extreme (zero, negative, 1e308, 1e-320, no unit, empty, NaN, lists
// with holes, paths that are files, folders, devices or missing), and random input files with
// extreme cells. Whatever the flags, three things must hold:
//   1. the exit status is 0 or 2 (1 is a bug; a timeout is a hang);
//   2. no inf or NaN reaches the table, the CSV, the JSON or a written file;
//   3. a refusal (status 2 with nothing on stdout) is one line, "uphill: …", naming one of the
//      flags or files given; no line of FFmpeg or OpenCV comes before it.
// Truth: the program's own contract (docs/exit-codes.md), not its answers.
//
// Draws: each command's flags are drawn per process run (about 270 runs), and the model's inputs
// are also drawn at the level of the library the program calls, many per process: each row of a
// `convert --batch` CSV is one drawn setting (body, lengths, angles, rod, uncertainties, every
// cell sometimes extreme) that goes through the same configuration reader, range checks
// (model/input_ranges.hpp), converter and printer as one setting given by flags — 10,000 rows in
// 10 runs (ConvertBatchRows). A process per draw would take minutes.
//
// Reproducible: UPHILL_PROPERTY_SEED=<n> picks the draws (default fixed, printed by each test);
// a failure prints the seed and the command line. UPHILL_PROPERTY_SCALE multiplies the number of
// runs (the sanitizer build defaults to a quarter).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "file_test_support.hpp"
#include "tiny_clip_suite.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

#ifndef UPHILL_PROPERTY_DEFAULT_SCALE
#define UPHILL_PROPERTY_DEFAULT_SCALE 1.0
#endif

std::uint64_t Seed() {
  const char* s = std::getenv("UPHILL_PROPERTY_SEED");
  static const std::uint64_t seed = s ? std::strtoull(s, nullptr, 10) : 20261123;
  static const bool printed = (std::cout << "UPHILL_PROPERTY_SEED=" << seed << " (set it to draw other values)\n", true);
  (void)printed;
  return seed;
}

int Runs(int release_runs) {
  const char* s = std::getenv("UPHILL_PROPERTY_SCALE");
  const double scale = s ? std::atof(s) : UPHILL_PROPERTY_DEFAULT_SCALE;
  return std::max(1, static_cast<int>(release_runs * scale + 0.5));
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// One flag and its value ("" flag: a positional argument; `bare`: a flag without value).
struct Arg {
  std::string flag, value;
  bool bare = false;
};

struct Outcome {
  int status = -1;
  std::string out, err, command;
};

Outcome RunProgram(const std::vector<std::string>& words, const std::vector<Arg>& args, const fs::path& work) {
  std::string command = "cd " + ShellQuote(work.string()) + " && timeout -s KILL 60 " + ShellQuote(UPHILL_PROGRAM);
  for (const std::string& w : words) command += " " + ShellQuote(w);
  for (const Arg& a : args) {
    if (!a.flag.empty()) command += " " + a.flag;
    if (!a.bare) command += " " + ShellQuote(a.value);
  }
  Outcome o;
  o.command = command;
  const int raw = std::system((command + " > " + ShellQuote((work / ".out").string()) + " 2> " +
                               ShellQuote((work / ".err").string()))
                                  .c_str());
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  o.out = testing::ReadBytes(work / ".out");
  o.err = testing::ReadBytes(work / ".err");
  return o;
}

// "inf", "nan", "infinity" as a token (not inside a word such as "information"), any case.
bool HasInfOrNan(const std::string& text) {
  std::string s = text;
  // Base64 images in HTML and SVG are not numbers.
  for (std::size_t at; (at = s.find("base64,")) != std::string::npos;) {
    const std::size_t end = s.find_first_of("\"')", at);
    s.erase(at, end == std::string::npos ? std::string::npos : end - at);
  }
  for (std::size_t i = 0; i + 3 <= s.size(); ++i) {
    const auto lower = [&](std::size_t k) { return static_cast<char>(std::tolower(static_cast<unsigned char>(s[k]))); };
    const bool inf = lower(i) == 'i' && lower(i + 1) == 'n' && lower(i + 2) == 'f';
    const bool nan = lower(i) == 'n' && lower(i + 1) == 'a' && lower(i + 2) == 'n';
    if (!inf && !nan) continue;
    std::size_t end = i + 3;
    if (inf && s.compare(i, 8, std::string("infinity")) == 0) end = i + 8;
    const bool before = i == 0 || !std::isalnum(static_cast<unsigned char>(s[i - 1]));
    const bool after = end >= s.size() || !std::isalnum(static_cast<unsigned char>(s[end]));
    // Input quoted back in a message ("'nan' is not a finite number") is not an output.
    const std::size_t open = i > 0 && (s[i - 1] == '-' || s[i - 1] == '+') ? i - 1 : i;
    const bool quoted = open > 0 && s[open - 1] == '\'' && end < s.size() && s[end] == '\'';
    if (before && after && !quoted) return true;
  }
  return false;
}

// Checks the three properties; `written`: files the run may have written (scanned if present).
void Check(const Outcome& o, const std::vector<Arg>& args, const std::vector<std::string>& words,
           const std::vector<fs::path>& written) {
  const std::string where = "\n  reproduce: UPHILL_PROPERTY_SEED=" + std::to_string(Seed()) + "\n  " + o.command +
                            "\n  stderr: " + o.err.substr(0, 600);
  EXPECT_TRUE(o.status == 0 || o.status == 2) << "exit status " << o.status << where;
  EXPECT_FALSE(HasInfOrNan(o.out)) << "inf/nan on stdout: " << o.out.substr(0, 600) << where;
  for (const fs::path& p : written) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) continue;
    const std::string ext = p.extension().string();
    if (ext == ".png" || ext == ".mp4" || ext == ".svg") continue;
    EXPECT_FALSE(HasInfOrNan(testing::ReadBytes(p))) << "inf/nan in " << p << where;
  }
  std::istringstream lines(o.err);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("uphill: ", 0) != 0)
      ADD_FAILURE() << "a line on stderr that is not uphill's: " << line << where;
  if (o.status == 2 && o.out.empty()) {
    // The refusal: its last line (rows left out may be named before it, one line each) names a
    // flag ("--x0: is required" names one not given) or a file given.
    EXPECT_FALSE(o.err.empty()) << "a refusal without a message" << where;
    std::string last = o.err.substr(0, o.err.empty() ? 0 : o.err.size() - 1);
    last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
    bool named = last.find("--") != std::string::npos || last.find(" -o") != std::string::npos;
    for (const Arg& a : args)
      if (!a.value.empty() && a.value.find_first_of("/.") != std::string::npos &&
          last.find(fs::path(a.value).filename().string()) != std::string::npos)
        named = true;
    for (const std::string& w : words)
      if (w.find('/') != std::string::npos && last.find(fs::path(w).filename().string()) != std::string::npos) named = true;
    EXPECT_TRUE(named) << "the refusal names none of the flags or files given" << where;
  }
}

// ---- the draws ------------------------------------------------------------------------------

class Draw {
 public:
  explicit Draw(std::uint64_t salt) : rng_(Seed() * 1000003 + salt) {}

  bool Chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  int Int(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  template <class T>
  const T& Pick(const std::vector<T>& v) {
    return v[static_cast<std::size_t>(Int(0, static_cast<int>(v.size()) - 1))];
  }
  std::string Num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
  }

  // A number that breaks something: a zero, a sign, an overflow or underflow, no number at all.
  std::string ExtremeNumber() {
    static const std::vector<std::string> pool = {
        "0", "-0", "-1", "1e308", "-1e308", "1.7976931348623157e308", "1e309", "1e-320", "4.9e-324", "1e-300",
        "1e300", "1e154", "1e-154", "1e20", "-1e20", "1e-20", "nan", "NaN", "inf", "-inf", "0x10", "1e", "",
        " ", "1,5", "12abc", "+-5", "1e-170", "9.999999999999999e307"};
    return Pick(pool);
  }
  // A quantity: usually a plausible value in [lo, hi] `unit`; otherwise extreme.
  std::string Quantity(double lo, double hi, const std::string& unit, const std::vector<std::string>& units) {
    if (Chance(plain_)) return Num(Uniform(lo, hi)) + unit;
    if (Chance(0.2)) return ExtremeNumber();  // without a unit
    return ExtremeNumber() + Pick(units);
  }
  std::string Length(double lo_mm, double hi_mm) { return Quantity(lo_mm, hi_mm, "mm", {"mm", "m", "km", "um", "in"}); }
  std::string Angle(double lo_deg, double hi_deg) { return Quantity(lo_deg, hi_deg, "deg", {"deg", "rad"}); }
  std::string Plain(double lo, double hi) { return Chance(plain_) ? Num(Uniform(lo, hi)) : ExtremeNumber(); }
  // How often a quantity is plausible (else extreme): 0.7, more for a setting whose many cells
  // should mostly reach the converter.
  void SetPlain(double p) { plain_ = p; }
  std::string Count(int lo, int hi) {
    if (Chance(0.75)) return std::to_string(Int(lo, hi));
    return Pick(std::vector<std::string>{"0", "-1", "-100", "18446744073709551616", "99999999999", "1e6", "3.5", "",
                                         "abc", "9223372036854775807"});
  }
  // A comma list of `n` quantities, sometimes with a hole.
  std::string List(const std::function<std::string()>& item) {
    std::string out;
    const int n = Int(1, 4);
    for (int i = 0; i < n; ++i) out += (i ? "," : "") + (Chance(0.05) ? std::string() : item());
    return out;
  }

  // The scene flags of convert/simulate/track/analyse-track.
  std::vector<Arg> Scene(bool allow_cone = true) {
    std::vector<Arg> a;
    const std::string body = Chance(0.05) ? ExtremeNumber() : Pick(std::vector<std::string>{"sphere", "spheroid", "double-cone"});
    if (body != "double-cone" || allow_cone) a.push_back({"--body", body});
    if (body == "sphere") a.push_back({"--R", Length(5, 50)});
    if (body == "spheroid") {
      a.push_back({"--a", Length(10, 30)});
      a.push_back({"--b", Length(10, 40)});
    }
    if (body == "double-cone") {
      a.push_back({"--R", Length(20, 60)});
      a.push_back({"--h", Length(40, 120)});
    }
    if (Chance(0.6)) {
      a.push_back({"--L", Length(300, 2000)});
      a.push_back({"--H", Length(10, 400)});
      a.push_back({"--D", Length(20, 300)});
      if (Chance(0.1)) a.push_back({"--L-along-rail", "", true});
    } else {
      a.push_back({"--theta", Angle(0.2, 30)});
      a.push_back({"--alpha", Angle(5, 150)});
    }
    if (Chance(0.15)) a.push_back({"--rod-diameter", Length(2, 20)});
    if (Chance(0.05)) a.push_back({"--a", Length(1, 10)});  // sometimes a dimension the body does not have
    return a;
  }
  std::vector<Arg> Uncertainties() {
    std::vector<Arg> a;
    for (const char* q : {"--u-L", "--u-H", "--u-D", "--u-R", "--u-a", "--u-theta", "--u-alpha"})
      if (Chance(0.2)) a.push_back({q, std::string(q).find("theta") != std::string::npos || std::string(q).find("alpha") != std::string::npos
                                           ? Angle(0.001, 0.5)
                                           : Length(0.01, 2)});
    return a;
  }

 private:
  std::mt19937_64 rng_;
  double plain_ = 0.7;
};

// A fresh working folder per run (outputs, inputs).
fs::path Work(const std::string& name) { return testing::FreshFolder("property-" + name); }

// Removes a run's folder, or, when the test has failed so far, keeps a copy for the person
// reproducing it (its path is printed).
void Done(const fs::path& work) {
  static int seen = 0;  // failures recorded so far in this test (a new one: this run failed)
  static const ::testing::TestInfo* test = nullptr;
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  if (info != test) test = info, seen = 0;
  const int parts = info->result()->total_part_count();
  const bool failed = parts > seen;
  seen = parts;
  if (failed) {
    static int kept = 0;
    const fs::path keep = fs::temp_directory_path() / ("uphill-property-failure-" + std::to_string(::getpid()) + "-" +
                                                      std::to_string(++kept));
    std::error_code ec;
    fs::remove_all(keep, ec);
    fs::copy(work, keep, fs::copy_options::recursive, ec);
    if (kept <= 20) std::cerr << "  inputs kept in " << keep << "\n";
  }
  fs::remove_all(work);
}

// ---- the commands ---------------------------------------------------------------------------

TEST(CliProperty, Convert) {
  Draw d(1);
  for (int i = 0, n = Runs(80); i < n; ++i) {
    const fs::path work = Work("convert");
    std::vector<Arg> a = d.Scene();
    for (Arg& u : d.Uncertainties()) a.push_back(u);
    if (d.Chance(0.3)) a.push_back({"--mu", d.Plain(0, 0.2)});
    if (d.Chance(0.3)) a.push_back({"--at-x", d.List([&] { return d.Length(1, 800); })});
    if (d.Chance(0.5)) a.push_back({"--mc-trials", d.Count(100, 2000)});
    if (d.Chance(0.1)) a.push_back({"--seed", d.Count(0, 1000000)});
    if (d.Chance(0.1)) a.push_back({"--length-unit", d.Pick(std::vector<std::string>{"mm", "cm", "m", "in", "furlong", ""})});
    const int format = d.Int(0, 2);
    if (format == 1) a.push_back({"--json", "", true});
    if (format == 2) a.push_back({"--csv", "", true});
    if (d.Chance(0.05)) a.push_back({"--json", "", true});
    const Outcome o = RunProgram({"convert"}, a, work);
    Check(o, a, {}, {});
    if (o.status == 0 && format == 1 && !o.out.empty()) {
      EXPECT_TRUE(json::accept(o.out)) << o.command;
    }
    Done(work);
  }
}

TEST(CliProperty, ConvertBatch) {
  Draw d(2);
  for (int i = 0, n = Runs(15); i < n; ++i) {
    const fs::path work = Work("convert-batch");
    std::ofstream csv(work / "batch.csv");
    csv << "label,body,R,a,b,L,H,D,u_D,note\n";
    for (int r = 0; r < 6; ++r)
      csv << "r" << r << "," << d.Pick(std::vector<std::string>{"sphere", "spheroid", "double-cone", "cube"}) << ","
          << d.Length(5, 50) << "," << d.Length(10, 30) << "," << d.Length(10, 40) << "," << d.Length(300, 2000) << ","
          << d.Length(10, 400) << "," << d.Length(20, 300) << "," << (d.Chance(0.5) ? d.Length(0.01, 2) : "") << ",\n";
    csv.close();
    std::vector<Arg> a = {{"--batch", "batch.csv"}, {"--mc-trials", d.Count(100, 500)}};
    if (d.Chance(0.5)) a.push_back({"--json", "", true});
    const Outcome o = RunProgram({"convert"}, a, work);
    Check(o, a, {}, {});
    Done(work);
  }
}

// The library-level draws (see the top): 1000 settings per batch, every column drawn. The rows'
// cells carry their units (column "L", not "L_mm"), so a cell may also lack one.
TEST(CliProperty, ConvertBatchRows) {
  Draw d(11);
  const std::vector<std::string> columns = {"body", "R", "a", "b", "h", "L", "H", "D", "theta", "alpha",
                                            "rod_diameter", "u_L", "u_H", "u_D", "u_R", "u_a", "u_theta", "u_alpha"};
  int rows_drawn = 0, converted = 0;
  for (int i = 0, n = Runs(10); i < n; ++i) {
    const fs::path work = Work("convert-rows");
    std::ofstream csv(work / "batch.csv");
    for (std::size_t c = 0; c < columns.size(); ++c) csv << (c ? "," : "") << columns[c];
    csv << "\n";
    for (int r = 0; r < 1000; ++r, ++rows_drawn) {
      d.SetPlain(d.Chance(0.5) ? 0.97 : 0.7);
      std::map<std::string, std::string> cell;
      for (const Arg& a : d.Scene()) cell[a.flag.substr(2) == "rod-diameter" ? "rod_diameter" : a.flag.substr(2)] = a.value;
      for (const Arg& a : d.Uncertainties()) cell[a.flag.substr(2).replace(1, 1, "_")] = a.value;
      for (std::size_t c = 0; c < columns.size(); ++c) {
        const std::string& v = cell[columns[c]];
        csv << (c ? "," : "") << (v.find_first_of(",\"") == std::string::npos ? v : "\"" + v + "\"");
      }
      csv << "\n";
    }
    csv.close();
    std::vector<Arg> a = {{"--batch", "batch.csv"}, {"--mc-trials", "100"}, {"--json", "", true}};
    if (d.Chance(0.5)) a.push_back({"--mu", d.Plain(0, 0.2)});
    const Outcome o = RunProgram({"convert"}, a, work);
    Check(o, a, {}, {});
    if (json::accept(o.out)) {
      for (const json& row : json::parse(o.out)) converted += !row.contains("error");
    } else {
      EXPECT_TRUE(o.out.empty()) << "not JSON: " << o.out.substr(0, 300) << "\n  " << o.command;
    }
    Done(work);
  }
  std::cout << "convert --batch rows drawn: " << rows_drawn << ", converted: " << converted << "\n";
  EXPECT_GT(converted, rows_drawn / 10);  // the draws reach the converter, not only the reader's refusals
}

TEST(CliProperty, FitXy) {
  Draw d(3);
  for (int i = 0, n = Runs(40); i < n; ++i) {
    const fs::path work = Work("fit-xy");
    const double scale = std::pow(10.0, d.Int(-200, 200));
    const bool uncertainties = d.Chance(0.6);
    std::ofstream csv(work / "xy.csv");
    csv << (uncertainties ? "X,Y,uX,uY\n" : "X,Y\n");
    const int rows = d.Int(0, 8);
    for (int r = 0; r < rows; ++r) {
      const double x = scale * (r + d.Uniform(0, 0.5));
      csv << (d.Chance(0.9) ? d.Num(x) : d.ExtremeNumber()) << "," << (d.Chance(0.9) ? d.Num(2 * x + scale) : d.ExtremeNumber());
      if (uncertainties) csv << "," << (d.Chance(0.9) ? d.Num(0.05 * scale) : d.ExtremeNumber()) << ","
                             << (d.Chance(0.9) ? d.Num(0.1 * scale) : d.ExtremeNumber());
      csv << "\n";
    }
    csv.close();
    std::vector<Arg> a = {{"--xy", "xy.csv"}};
    if (d.Chance(0.8)) a.push_back({"--method", d.Pick(std::vector<std::string>{"ols", "wls", "york", "robust", "lasso"})});
    const bool as_json = d.Chance(0.5);
    if (as_json) a.push_back({"--json", "", true});
    if (d.Chance(0.05)) a.push_back({"--mc-trials", d.Count(100, 1000)});
    const Outcome o = RunProgram({"fit"}, a, work);
    Check(o, a, {}, {});
    if (o.status == 0 && as_json) {
      EXPECT_TRUE(json::accept(o.out)) << o.command;
    }
    Done(work);
  }
}

// An experiment folder whose rows (and sometimes experiment.json) hold extreme values.
void WriteExperiment(Draw& d, const fs::path& dir) {
  fs::create_directories(dir);
  json e = json::parse(testing::ReadBytes(fs::path(UPHILL_SOURCE_DIR) / "data/series1-fixed-D/experiment.json"));
  if (d.Chance(0.15)) e["body"]["a"] = d.Chance(0.5) ? d.Length(10, 20) : d.ExtremeNumber();
  if (d.Chance(0.1)) e["apparatus"]["H"] = d.Length(100, 400);
  if (d.Chance(0.1)) e["uncertainties"]["D"] = d.Length(0.1, 1e6);
  std::ofstream(dir / "experiment.json") << e.dump(2);
  std::ofstream csv(dir / "measurements.csv");
  csv << "trial,series,L_mm,D_mm,Y_mm,note\n";
  for (int r = 0; r < d.Int(1, 6); ++r) {
    const double L = d.Uniform(700, 1300);
    csv << "t" << r << ",s," << (d.Chance(0.85) ? d.Num(L) : d.ExtremeNumber()) << ","
        << (d.Chance(0.85) ? d.Num(d.Uniform(100, 200)) : d.ExtremeNumber()) << ","
        << (d.Chance(0.85) ? d.Num(L * 0.3) : d.ExtremeNumber()) << ",\n";
  }
}

TEST(CliProperty, FitExperiment) {
  Draw d(4);
  for (int i = 0, n = Runs(15); i < n; ++i) {
    const fs::path work = Work("fit-experiment");
    WriteExperiment(d, work / "exp");
    std::vector<Arg> a = {{"", "exp"}, {"--mc-trials", d.Count(100, 300)}};
    if (d.Chance(0.5)) a.push_back({"--json", "", true});
    const Outcome o = RunProgram({"fit"}, a, work);
    Check(o, a, {}, {});
    Done(work);
  }
}

TEST(CliProperty, Report) {
  Draw d(5);
  for (int i = 0, n = Runs(5); i < n; ++i) {
    const fs::path work = Work("report");
    WriteExperiment(d, work / "exp");
    std::string out = "out";
    const int kind = d.Int(0, 5);
    if (kind == 1) {
      std::ofstream(work / "afile") << "x";
      out = "afile";
    }
    if (kind == 2) out = "exp";  // into the experiment itself: its own files must not be replaced
    if (kind == 3) out = "/dev/full";
    if (kind == 4) out = "";
    std::vector<Arg> a = {{"", "exp"}, {"-o", out}, {"--mc-trials", d.Count(100, 300)}};
    const std::string experiment_before = testing::ReadBytes(work / "exp/measurements.csv");
    const Outcome o = RunProgram({"report"}, a, work);
    std::vector<fs::path> written;
    for (const char* f : {"fit.json", "report.md", "report.html", "fit_y_vs_x.dat", "fit_offset.dat"}) written.push_back(work / out / f);
    Check(o, a, {}, kind == 3 || kind == 4 ? std::vector<fs::path>{} : written);
    EXPECT_EQ(testing::ReadBytes(work / "exp/measurements.csv"), experiment_before) << o.command;
    Done(work);
  }
}

TEST(CliProperty, Simulate) {
  Draw d(6);
  for (int i = 0, n = Runs(60); i < n; ++i) {
    const fs::path work = Work("simulate");
    std::vector<Arg> a = d.Scene();
    if (d.Chance(0.95)) a.push_back({"--x0", d.Length(1, 600)});
    if (d.Chance(0.4)) a.push_back({"--v0", d.Quantity(-1, 1, "m/s", {"m/s", "mm/s"})});
    if (d.Chance(0.2)) a.push_back({"--g", d.Quantity(1, 20, "m/s2", {"m/s2"})});
    if (d.Chance(0.3)) a.push_back({"--mu", d.Plain(0, 0.1)});
    const int mode = d.Int(0, 3);
    if (mode == 0 || d.Chance(0.05)) a.push_back({"--dt", d.Quantity(5, 200, "ms", {"ms", "s"})});
    if (mode == 1 || d.Chance(0.05)) a.push_back({"--at-times", d.List([&] { return d.Quantity(0, 2, "s", {"s", "ms"}); })});
    if (mode == 2 || d.Chance(0.05)) a.push_back({"--at-x", d.List([&] { return d.Length(1, 600); })});
    if (d.Chance(0.3)) a.push_back({"--t-end", d.Quantity(0.1, 5, "s", {"s", "ms"})});
    if (d.Chance(0.3)) a.push_back({"--method", d.Pick(std::vector<std::string>{"quadrature", "ode", "auto", "euler"})});
    const int format = d.Int(0, 2);
    if (format == 1) a.push_back({"--json", "", true});
    if (format == 2) a.push_back({"--csv", "", true});
    const Outcome o = RunProgram({"simulate"}, a, work);
    Check(o, a, {}, {});
    if (o.status == 0 && format == 1) {
      EXPECT_TRUE(json::accept(o.out)) << o.command;
    }
    Done(work);
  }
}

// A track CSV of `frames` frames: at rest at x0, then accelerating away; with probability `odd`
// (and a few lost frames) a cell is extreme. odd = 0: a plain, noise-free release.
void WriteTrack(Draw& d, const fs::path& file, int frames, double odd) {
  std::ofstream csv(file);
  csv << "frame,t,u,v,radius_px,x,z,quality\n";
  const double x0 = odd > 0 ? d.Uniform(5, 50) : 30.0;
  for (int f = 0; f < frames; ++f) {
    const double t = f / 120.0;
    const double x = t < 0.2 ? x0 : x0 + 0.5 * 9.81 * 0.05 * (t - 0.2) * (t - 0.2) * 1000;
    if (odd > 0 && d.Chance(odd)) {
      csv << f << "," << d.Num(t) << ",,,,,,0\n";
      continue;
    }
    const auto cell = [&](const std::string& plain, double p) { return odd > 0 && d.Chance(p * odd) ? d.ExtremeNumber() : plain; };
    csv << f << "," << cell(d.Num(t), 0.6) << ",400,300,20," << cell(d.Num(x + (odd > 0 ? d.Uniform(-0.3, 0.3) : 0.0)), 1.0)
        << ",10," << cell("0.7", 0.6) << "\n";
  }
}

TEST(CliProperty, AnalyseTrack) {
  Draw d(7);
  for (int i = 0, n = Runs(25); i < n; ++i) {
    const fs::path work = Work("analyse-track");
    WriteTrack(d, work / "track.csv", d.Int(0, 60), 0.05);
    std::vector<Arg> a = d.Scene();
    a.insert(a.begin(), {"", "track.csv"});
    if (d.Chance(0.3)) a.push_back({"--g", d.Quantity(1, 20, "m/s2", {"m/s2"})});
    if (d.Chance(0.3)) a.push_back({"--u-x", d.Length(0.05, 2)});
    if (d.Chance(0.3)) a.push_back({"--fit", d.Pick(std::vector<std::string>{"g", "mu", "both"})});
    const bool out = d.Chance(0.2);
    if (out) a.push_back({"-o", "analysis"});
    if (d.Chance(0.4)) a.push_back({"--json", "", true});
    const Outcome o = RunProgram({"analyse-track"}, a, work);
    Check(o, a, {}, out ? std::vector<fs::path>{work / "analysis/track_analysis.json", work / "analysis/track_x_vs_t.dat"}
                        : std::vector<fs::path>{});
    Done(work);
  }
}

// Regression: a position uncertainty or g outside model/input_ranges.hpp, on the command line
// and in an experiment's experiment.json, is refused naming it (exit 2) — it printed "inf mm" and
// wrote it into track_analysis.json. Truth: docs/exit-codes.md and the ranges' contract.
TEST(CliRanges, AnalyseTrackRefusesAnExtremeUncertaintyOrG) {
  Draw d(12);
  const fs::path work = Work("analyse-track-ranges");
  WriteTrack(d, work / "track.csv", 60, 0.0);
  const std::vector<Arg> scene = {{"", "track.csv"}, {"--body", "sphere"}, {"--R", "12.7mm"},
                                  {"--theta", "3deg"}, {"--alpha", "40deg"}};
  for (const auto& [flag, value] : std::vector<std::pair<std::string, std::string>>{
           {"--u-x", "1e308mm"}, {"--u-x", "1e-320mm"}, {"--g", "1e-308m/s2"}, {"--g", "1e308m/s2"}}) {
    std::vector<Arg> a = scene;
    a.push_back({flag, value});
    a.push_back({"-o", "out"});
    const Outcome o = RunProgram({"analyse-track"}, a, work);
    Check(o, a, {}, {work / "out/track_analysis.json"});
    EXPECT_EQ(o.status, 2) << o.command << "\n" << o.out;
    EXPECT_NE(o.err.find(flag + ": must be > 0, between"), std::string::npos) << o.err;
  }
  std::vector<Arg> plain = scene;
  plain.push_back({"--u-x", "0.3mm"});
  const Outcome ok = RunProgram({"analyse-track"}, plain, work);
  EXPECT_EQ(ok.status, 0) << ok.err;
  Done(work);
}

TEST(CliRanges, ExperimentJsonRefusesAnExtremeVideoUncertaintyOrG) {
  const fs::path work = Work("experiment-ranges");
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"u_x", "1e308 mm"}, {"u_x", "1e-320 mm"}, {"g", "1e-308 m/s2"}}) {
    fs::remove_all(work / "exp");
    fs::create_directories(work / "exp");
    json e = json::parse(testing::ReadBytes(fs::path(UPHILL_SOURCE_DIR) / "data/series1-fixed-D/experiment.json"));
    e["format"] = "uphill-experiment/2";
    e["video_analysis"] = {{key, value}};
    std::ofstream(work / "exp/experiment.json") << e.dump(2);
    fs::copy_file(fs::path(UPHILL_SOURCE_DIR) / "data/series1-fixed-D/measurements.csv", work / "exp/measurements.csv");
    const std::vector<Arg> a = {{"", "./exp"}, {"--mc-trials", "100"}};
    const Outcome o = RunProgram({"fit"}, a, work);
    Check(o, a, {}, {});
    EXPECT_EQ(o.status, 2) << o.command;
    EXPECT_NE(o.err.find("video_analysis." + key + ": must be > 0, between"), std::string::npos) << o.err;
  }
  Done(work);
}

TEST(CliProperty, CalibrateTargetAndScene) {
  Draw d(8);
  const fs::path clip = testing::FreshFolder("property-calibrate-clip");
  for (int i = 0, n = Runs(20); i < n; ++i) {
    const fs::path work = Work("calibrate");
    if (d.Chance(0.5)) {
      std::vector<Arg> a = {{"--cols", d.Count(3, 12)}, {"--rows", d.Count(3, 12)}, {"--square", d.Length(5, 40)},
                            {"-o", d.Pick(std::vector<std::string>{"board.svg", "board.png", "board.pdf", "/dev/full", "nodir/b.svg"})}};
      if (d.Chance(0.4)) a.push_back({"--dpi", d.Plain(72, 600)});
      const Outcome o = RunProgram({"calibrate", "target"}, a, work);
      Check(o, a, {}, {work / "board.svg"});
    } else {
      // A camera file, and points with extreme cells.
      std::ofstream(work / "cam.json")
          << json({{"format", "uphill-camera/1"}, {"image_width_px", 1280}, {"image_height_px", 720}, {"fx_px", 1300.0},
                   {"fy_px", 1300.0}, {"cx_px", 640.0}, {"cy_px", 360.0}, {"distortion", {-0.1, 0.02, 0, 0, 0}}})
                 .dump();
      std::ofstream csv(work / "points.csv");
      csv << "name,u,v,x_mm,y_mm,z_mm\n";
      for (int p = 0; p < d.Int(0, 9); ++p)
        csv << "P" << p << "," << (d.Chance(0.9) ? d.Num(d.Uniform(0, 1279)) : d.ExtremeNumber()) << ","
            << (d.Chance(0.9) ? d.Num(d.Uniform(0, 719)) : d.ExtremeNumber()) << ","
            << (d.Chance(0.9) ? d.Num(d.Uniform(0, 1200)) : d.ExtremeNumber()) << ","
            << (d.Chance(0.9) ? d.Num(d.Uniform(-80, 80)) : d.ExtremeNumber()) << ","
            << (d.Chance(0.9) ? d.Num(d.Uniform(0, 300)) : d.ExtremeNumber()) << "\n";
      csv.close();
      std::vector<Arg> a = {{"--camera", "cam.json"}, {"--points", "points.csv"},
                            {"-o", d.Pick(std::vector<std::string>{"scene.json", "cam.json", "points.csv", "/dev/full"})}};
      const Outcome o = RunProgram({"calibrate", "scene"}, a, work);
      Check(o, a, {}, {work / "scene.json"});
    }
    Done(work);
  }
  fs::remove_all(clip);
}

// The tiny clip for `track`, made once (tools/make_video).
class TrackProperty : public testing::TinyClipSuite {};

TEST_F(TrackProperty, Track) {
  Draw d(9);
  for (int i = 0, n = Runs(8); i < n; ++i) {
    const fs::path work = Work("track");
    CopyClipInto(work);
    std::vector<Arg> a = {{"", "clip.mp4"}, {"--camera", "cam.json"}, {"--scene", "scene.json"}};
    // The clip's own scene (make_video's default apparatus), sometimes with a flag drawn.
    std::vector<Arg> scene = {{"--body", "sphere"}, {"--R", "25.4mm"}, {"--L", "1000mm"}, {"--H", "100mm"},
                              {"--D", "150mm"}, {"--rod-diameter", "8mm"}};
    if (d.Chance(0.5)) scene = d.Scene(false);
    for (Arg& s : scene) a.push_back(s);
    a.push_back({"-o", d.Pick(std::vector<std::string>{"track.csv", "out/track.csv", "clip.mp4", "/dev/full", "cam.json"})});
    if (d.Chance(0.3)) a.push_back({"--overlay", d.Pick(std::vector<std::string>{"overlay.mp4", "clip.mp4", "./clip.mp4", "nodir/o.mp4"})});
    if (d.Chance(0.3)) a.push_back({"--init", d.Pick(std::vector<std::string>{"200,130", "1e308,5", "-5,-5", "nan,1", "", "3"})});
    if (d.Chance(0.3)) a.push_back({"--analyse", "", true});
    a.push_back({"--quiet", "", true});
    const std::string video_before = testing::ReadBytes(work / "clip.mp4");
    const Outcome o = RunProgram({"track"}, a, work);
    Check(o, a, {}, {work / "track.csv", work / "track.csv.json", work / "out/track.csv", work / "track_analysis.json"});
    EXPECT_EQ(testing::ReadBytes(work / "clip.mp4"), video_before) << "the input video was changed\n  " << o.command;
    Done(work);
  }
}

TEST(CliProperty, PaperFigures) {
  Draw d(10);
  for (int i = 0, n = Runs(2); i < n; ++i) {
    const fs::path work = Work("paper-figures");
    std::ofstream(work / "afile") << "x";
    std::vector<Arg> a = {{"-o", d.Pick(std::vector<std::string>{"figures", "afile", "/dev/full", "figures"})}};
    if (d.Chance(0.5)) a.push_back({"--data", d.Pick(std::vector<std::string>{std::string(UPHILL_SOURCE_DIR) + "/data", "nodata", "afile"})});
    const Outcome o = RunProgram({"paper-figures"}, a, work);
    Check(o, a, {}, {work / "figures/index.html", work / "figures/fig_potential.dat"});
    Done(work);
  }
}

}  // namespace
}  // namespace uphill
