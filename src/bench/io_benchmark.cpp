#include "bench/io_benchmark.hpp"

#include <fast_float/fast_float.h>

#include <algorithm>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/uniform_real_distribution.hpp>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <malloc.h>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "bench/synthetic_data.hpp"
#include "io/csv_records.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "oracle/line_references.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;

// The lab spheroid of the convert files (flags of `uphill convert`, metres for the peer).
constexpr const char* kA = "15.875mm";
constexpr const char* kB = "25.4mm";
constexpr double kAm = 0.015875, kBm = 0.0254;

// Buffered writing of a large text file.
class TextFile {
 public:
  explicit TextFile(const fs::path& path) : file_(std::fopen(path.c_str(), "wb")), path_(path) {
    if (!file_) throw EnvironmentError("cannot write " + path.string());
    buffer_.reserve(kBlock + 256);
  }
  ~TextFile() { Close(); }
  void Put(std::string_view s) {
    buffer_ += s;
    if (buffer_.size() >= kBlock) Flush();
  }
  void Number(double v) {
    char text[32];
    Put(std::string_view(text, std::to_chars(text, text + sizeof text, v).ptr));
  }
  void Fixed(double v, int digits) {
    char text[48];
    Put(std::string_view(text, std::to_chars(text, text + sizeof text, v, std::chars_format::fixed, digits).ptr));
  }
  std::uint64_t offset() const { return written_ + buffer_.size(); }
  void Close() {
    if (!file_) return;
    Flush();
    if (std::fclose(file_) != 0) throw EnvironmentError("cannot write " + path_.string());
    file_ = nullptr;
  }

 private:
  static constexpr std::size_t kBlock = std::size_t{1} << 20;
  void Flush() {
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      throw EnvironmentError("cannot write " + path_.string());
    written_ += buffer_.size();
    buffer_.clear();
  }
  std::FILE* file_;
  fs::path path_;
  std::string buffer_;
  std::uint64_t written_ = 0;
};

// X,Y,uX,uY with every double in its shortest round-trip form (the file holds exactly `d`).
// Returns the byte offsets where rows n − 10 and n − 5 start (for the bad-input cases).
std::pair<std::uint64_t, std::uint64_t> WriteXy(const fs::path& path, const LineData& d) {
  TextFile f(path);
  f.Put("X,Y,uX,uY\n");
  const std::size_t n = d.size();
  std::pair<std::uint64_t, std::uint64_t> marks{0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 10 == n) marks.first = f.offset();
    if (i + 5 == n) marks.second = f.offset();
    f.Number(d.x[i]), f.Put(","), f.Number(d.y[i]), f.Put(","), f.Number(d.u_x[i]), f.Put(","), f.Number(d.u_y[i]);
    f.Put("\n");
  }
  f.Close();
  return marks;
}

// L_mm,H_mm,D_mm of random settings over the apparatus' range, to 0.01 mm as measured.
std::uint64_t WriteSettings(const fs::path& path, std::size_t n, std::uint64_t seed) {
  boost::random::mt19937_64 engine(seed);
  boost::random::uniform_real_distribution<double> L(500, 2000), H(50, 500), D(20, 250);
  TextFile f(path);
  f.Put("L_mm,H_mm,D_mm\n");
  std::uint64_t near_end = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 10 == n) near_end = f.offset();
    f.Fixed(L(engine), 2), f.Put(","), f.Fixed(H(engine), 2), f.Put(","), f.Fixed(D(engine), 2), f.Put("\n");
  }
  f.Close();
  return near_end;
}

struct Outcome {
  ProcessRun run;  // the best (least CPU) run; peak_bytes: the largest over the runs
  std::string out_path, err_path;
};

Outcome Repeat(int repeats, const std::vector<std::string>& argv, const fs::path& dir, const std::string& name,
               bool keep_output) {
  Outcome o;
  o.out_path = keep_output ? (dir / (name + ".out")).string() : "";
  o.err_path = (dir / (name + ".err")).string();
  for (int r = 0; r < repeats; ++r) {
    const ProcessRun run = RunProcess(argv, o.out_path, o.err_path);
    if (r == 0 || run.cpu_seconds < o.run.cpu_seconds) {
      const std::uint64_t peak = std::max(o.run.peak_bytes, run.peak_bytes);
      o.run = run;
      o.run.peak_bytes = peak;
    } else {
      o.run.peak_bytes = std::max(o.run.peak_bytes, run.peak_bytes);
    }
  }
  return o;
}

std::string ReadText(const std::string& path, std::size_t limit = std::size_t{1} << 20) {
  std::ifstream in(path, std::ios::binary);
  std::string text(limit, '\0');
  in.read(text.data(), static_cast<std::streamsize>(limit));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

std::string FirstLine(const std::string& path) {
  const std::string text = ReadText(path, 4096);
  return text.substr(0, text.find('\n'));
}

// Column `name`'s numbers of a CSV file, read with the program's own reader.
std::vector<double> Column(const std::string& path, const std::string& name) {
  CsvRecords records(path);
  const int column = records.Column(name);
  if (column < 0) throw std::runtime_error(path + ": no column " + name);
  std::vector<double> out;
  CsvRecords::Record r;
  while (records.Next(&r)) {
    double v = NAN;
    const std::string_view cell = r.cells.at(static_cast<std::size_t>(column));
    fast_float::from_chars(cell.data(), cell.data() + cell.size(), v);
    out.push_back(v);
  }
  return out;
}

std::string Ratio(double peer, double ours) { return peer > 0 && ours > 0 ? FormatRatio(peer / ours) : ""; }

std::string OfFile(std::uint64_t peak, std::uint64_t file) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", static_cast<double>(peak) / static_cast<double>(file));
  return text;
}

constexpr const char* kMethod =
    "Each workload runs the real program as its own process, as a user meets it: `uphill fit --xy FILE "
    "--method M` (text output), `uphill fit --xy FILE --json` (every row's results streamed, to /dev/null) and "
    "`uphill convert --batch FILE --body spheroid --a 15.875mm --b 25.4mm --csv` (one output line per row, to "
    "a file). Its peer is tools/bench/io_peers.py in its own process: the interpreter's start, `import numpy`, "
    "np.loadtxt of the same file and numpy.linalg.lstsq (ols) or the NumPy York iteration (york), or the "
    "conversion's formulas; for convert once without output (\"loadtxt + convert\") and once writing the same "
    "columns with np.savetxt (\"+ savetxt\"). Time: CPU time (user + system) of the whole process, best of the "
    "repeats (one at 10^7 rows); ratio = NumPy's / uphill's. Peak RSS: the process's ru_maxrss, and its ratio "
    "to the input file's size. Files: X,Y,uX,uY with every double in shortest round-trip form (~76 bytes a "
    "row); L_mm,H_mm,D_mm to 0.01 mm. Accuracy: uphill's slope, intercept and their standard errors from "
    "`--json --no-rows` against the extended-precision oracle of the same doubles (src/oracle), NumPy's slope "
    "and intercept likewise; for convert, the largest difference between uphill's printed values and "
    "NumPy's (np.savetxt, same formats): agreement to the printed digits.";

}  // namespace

void RunIoBenchmark(const IoBenchmarkOptions& f, std::ostream& out) {
  if (f.repeats < 1) throw InputError("--repeats", "must be at least 1");
  for (std::uint64_t n : f.sizes)
    if (n < 20) throw InputError("--sizes", "every size must be at least 20");
  Section section = StartSection("io", f.common.command, kMethod);
  std::error_code ec;
  const std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  std::optional<TemporaryDirectory> temporary;
  fs::path dir = f.folder;
  if (dir.empty()) {
    temporary.emplace();
    dir = temporary->path();
  } else {
    fs::create_directories(dir);
  }
  std::string script = f.script.empty() ? FindUpward("tools/bench/io_peers.py") : f.script;
  const std::string why_not = PeerUnavailable(f.no_peers ? "--no-peers" : "", f.common.python, script,
                                              "tools/bench/io_peers.py not found (use --peer-script)", "numpy");
  if (!why_not.empty()) {
    script.clear();
    section.notes.push_back("NumPy peer skipped: " + why_not);
  }
  const std::vector<std::string> python = {"/usr/bin/env", "OMP_NUM_THREADS=1", "OPENBLAS_NUM_THREADS=1",
                                           "MKL_NUM_THREADS=1", f.common.python, script};
  out << "uphill bench io: the programs end to end as processes (CPU time = user + system, best of " << f.repeats
      << " at N <= 10^6, one run above), peak RSS = ru_maxrss; files in " << dir.string() << "\n"
      << (why_not.empty() ? "" : "NumPy peer skipped: " + why_not + "\n") << "\n";

  Table table({{"workload", 22, true},
               {"N", 5},
               {"file", 7},
               {"uphill", 9},
               {"peak RSS", 8},
               {"/file", 5},
               {"accuracy", 9},
               {"peer (NumPy)", 18, true},
               {"peer time", 9},
               {"peer RSS", 8},
               {"ratio", 6},
               {"peer acc.", 9}});
  table.Start(out);
  struct Goal {
    std::string what;
    double ratio, memory;
  };
  std::vector<Goal> at_million;
  bool versions_added = false;
  fs::path largest_xy, largest_settings;
  std::pair<std::uint64_t, std::uint64_t> xy_marks{0, 0};
  std::uint64_t settings_mark = 0;
  std::size_t largest = 0;
  for (std::uint64_t n64 : f.sizes) {
    const std::size_t n = static_cast<std::size_t>(n64);
    const int repeats = n <= 1'000'000 ? f.repeats : 1;
    const std::string tag = FormatCount(n64);
    // --- fit --xy ---
    // The data, their file and the oracles' references; then the data go before any program runs:
    // a child's ru_maxrss includes the anonymous memory of the process it was forked from.
    const fs::path xy = dir / ("xy_" + std::to_string(n) + ".csv");
    std::pair<std::uint64_t, std::uint64_t> marks;
    std::map<std::string, std::vector<double>> references;
    {
      const LineData d = StraightLine(n, f.seed + n, 0.0, 10.0, 1.0);
      marks = WriteXy(xy, d);
      references["ols"] = oracle::OrdinaryLeastSquares(d).Values(true);
      references["york"] = oracle::YorkLine(d).Values(false);
    }
    malloc_trim(0);
    const std::uint64_t xy_bytes = fs::file_size(xy);
    for (const std::string method : {"ols", "york"}) {
      const std::vector<double>& ref = references.at(method);
      const Outcome ours = Repeat(repeats, {self, "fit", "--xy", xy.string(), "--method", method}, dir, "fit", false);
      if (ours.run.exit_status != 0) throw std::runtime_error("uphill fit failed: " + FirstLine(ours.err_path));
      const Outcome exact =
          Repeat(1, {self, "fit", "--xy", xy.string(), "--method", method, "--json", "--no-rows"}, dir, "fit_json", true);
      const nlohmann::json j = nlohmann::json::parse(ReadText(exact.out_path));
      const double dev = MaxRelativeDeviation({j.at("slope"), j.at("intercept"), j.at("u_slope"), j.at("u_intercept")}, ref);
      std::vector<std::string> row = {"fit --xy " + std::string(method), tag, FormatBytes(xy_bytes),
                                      FormatSeconds(ours.run.cpu_seconds), FormatBytes(ours.run.peak_bytes),
                                      OfFile(ours.run.peak_bytes, xy_bytes), FormatDeviation(dev)};
      double ratio = 0;
      if (!script.empty()) {
        std::vector<std::string> argv = python;
        argv.insert(argv.end(), {"fit", xy.string(), "--method", method});
        const Outcome peer = Repeat(repeats, argv, dir, "peer", true);
        const nlohmann::json p = nlohmann::json::parse(ReadText(peer.out_path));
        if (!versions_added) {
          for (const auto& [name, version] : p.at("versions").items())
            section.versions.emplace_back(name, version.get<std::string>());
          versions_added = true;
        }
        ratio = peer.run.cpu_seconds / ours.run.cpu_seconds;
        row.insert(row.end(), {std::string("loadtxt + ") + (method == std::string("ols") ? "lstsq" : "York"),
                               FormatSeconds(peer.run.cpu_seconds), FormatBytes(peer.run.peak_bytes),
                               Ratio(peer.run.cpu_seconds, ours.run.cpu_seconds),
                               FormatDeviation(MaxRelativeDeviation({p.at("slope"), p.at("intercept")}, {ref[0], ref[1]}))});
      }
      table.Add(row);
      if (n == 1'000'000)
        at_million.push_back({"fit --xy " + std::string(method), ratio,
                              static_cast<double>(ours.run.peak_bytes) / static_cast<double>(xy_bytes)});
    }
    {  // --json with every row streamed
      const Outcome json = Repeat(repeats, {self, "fit", "--xy", xy.string(), "--method", "york", "--json"}, dir,
                                  "fit_rows", false);
      table.Add({"fit --xy york --json", tag, FormatBytes(xy_bytes), FormatSeconds(json.run.cpu_seconds),
                 FormatBytes(json.run.peak_bytes), OfFile(json.run.peak_bytes, xy_bytes), "as above",
                 "(rows streamed)"});
    }
    // --- convert --batch ---
    const fs::path settings = dir / ("settings_" + std::to_string(n) + ".csv");
    const std::uint64_t settings_near_end = WriteSettings(settings, n, f.seed + n);
    const std::uint64_t settings_bytes = fs::file_size(settings);
    const Outcome ours = Repeat(repeats,
                                {self, "convert", "--batch", settings.string(), "--body", "spheroid", "--a", kA, "--b",
                                 kB, "--csv"},
                                dir, "convert", true);
    if (ours.run.exit_status != 0) throw std::runtime_error("uphill convert failed: " + FirstLine(ours.err_path));
    std::vector<std::string> row = {"convert --batch --csv", tag, FormatBytes(settings_bytes),
                                    FormatSeconds(ours.run.cpu_seconds), FormatBytes(ours.run.peak_bytes),
                                    OfFile(ours.run.peak_bytes, settings_bytes), ""};
    if (!script.empty()) {
      std::vector<std::string> argv = python;
      argv.insert(argv.end(), {"convert", settings.string(), "--a", std::to_string(kAm), "--b", std::to_string(kBm)});
      const Outcome bare = Repeat(repeats, argv, dir, "peer", true);
      const fs::path numpy_csv = dir / "numpy_convert.csv";
      argv.insert(argv.end(), {"--out", numpy_csv.string()});
      const Outcome written = Repeat(repeats, argv, dir, "peer", true);
      // Agreement with NumPy to the printed digits.
      double angle = 0, length = 0;
      for (const std::string column : {"theta_deg", "alpha_deg", "phi_deg"}) {
        const std::vector<double> a = Column(ours.out_path, column), b = Column(numpy_csv.string(), column);
        for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) angle = std::max(angle, std::abs(a[i] - b[i]));
      }
      for (const std::string column : {"X_mm", "x_max_mm"}) {
        const std::vector<double> a = Column(ours.out_path, column), b = Column(numpy_csv.string(), column);
        for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
          length = std::max(length, std::abs(a[i] - b[i]) / std::abs(b[i]));
      }
      char accuracy[64];
      std::snprintf(accuracy, sizeof accuracy, "%.0e deg, %.0e", angle, length);
      row[6] = accuracy;
      row.insert(row.end(), {"loadtxt + convert", FormatSeconds(bare.run.cpu_seconds), FormatBytes(bare.run.peak_bytes),
                             Ratio(bare.run.cpu_seconds, ours.run.cpu_seconds), "(no output)"});
      table.Add(row);
      table.Add({"", "", "", "", "", "", "", "+ savetxt", FormatSeconds(written.run.cpu_seconds),
                 FormatBytes(written.run.peak_bytes), Ratio(written.run.cpu_seconds, ours.run.cpu_seconds),
                 "same formats"});
      // The goal's peer does the same work as the command: read, convert and write the columns.
      if (n == 1'000'000)
        at_million.push_back({"convert --batch --csv vs NumPy + savetxt (without output: " + Ratio(bare.run.cpu_seconds, ours.run.cpu_seconds) + ")",
                              written.run.cpu_seconds / ours.run.cpu_seconds,
                              static_cast<double>(ours.run.peak_bytes) / static_cast<double>(settings_bytes)});
    } else {
      table.Add(row);
    }
    std::error_code rm;
    fs::remove(dir / "numpy_convert.csv", rm);
    fs::remove(dir / "convert.out", rm);
    if (n >= largest) {
      if (!largest_xy.empty()) fs::remove(largest_xy, rm), fs::remove(largest_settings, rm);
      largest = n, largest_xy = xy, largest_settings = settings, xy_marks = marks, settings_mark = settings_near_end;
    } else {
      fs::remove(xy, rm), fs::remove(settings, rm);
    }
  }
  section.tables.emplace_back("", &table);

  for (const Goal& g : at_million) {
    char line[256];
    std::snprintf(line, sizeof line, "Goal at 10^6 rows, %s: %.1fx NumPy (goal >= 5x): %s; peak RSS %.2f x the file (goal <= 2): %s.",
                  g.what.c_str(), g.ratio, g.ratio >= 5 ? "met" : "NOT met", g.memory, g.memory <= 2 ? "met" : "NOT met");
    out << "\n" << line;
    section.results.push_back(std::string(line) + "  ");
  }
  out << "\n";

  // --- bad input at scale ---
  Table bad({{"bad input", 34, true}, {"exit", 4}, {"uphill", 9}, {"peak RSS", 8}, {"first message (stderr)", 0, true}});
  if (!f.no_bad_input && largest > 0) {
    out << "\nBad input (the largest files, N = " << FormatCount(largest) << "):\n";
    bad.Start(out);
    const auto add = [&](const std::string& what, const Outcome& o, const std::string& extra) {
      std::string message = FirstLine(o.err_path);
      if (message.size() > 110) message = message.substr(0, 107) + "...";
      bad.Add({what, std::to_string(o.run.exit_status), FormatSeconds(o.run.cpu_seconds), FormatBytes(o.run.peak_bytes),
               message + extra});
    };
    // One bad cell near the end: the X of row N − 8 made non-numeric, in place (same length).
    const auto patch = [](const fs::path& path, std::uint64_t at, char c) {
      std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
      file.seekg(static_cast<std::streamoff>(at));
      char old = 0;
      file.get(old);
      file.seekp(static_cast<std::streamoff>(at));
      file.put(c);
      return old;
    };
    {
      const char old = patch(largest_xy, xy_marks.first, 'x');
      const Outcome o = Repeat(1, {self, "fit", "--xy", largest_xy.string(), "--method", "york"}, dir, "bad", true);
      patch(largest_xy, xy_marks.first, old);
      const std::string text = ReadText(o.out_path, 256);
      add("fit --xy: one bad cell, row N - 8", o,
          std::string(" | fit of the others: ") + (text.rfind("method: york, n = ", 0) == 0 ? "printed" : "MISSING"));
    }
    {
      const char old = patch(largest_settings, settings_mark, 'x');
      const Outcome o = Repeat(1,
                               {self, "convert", "--batch", largest_settings.string(), "--body", "spheroid", "--a", kA,
                                "--b", kB, "--csv"},
                               dir, "bad", true);
      patch(largest_settings, settings_mark, old);
      std::uint64_t lines = 0;
      {
        std::ifstream in(o.out_path, std::ios::binary);
        std::string line;
        while (std::getline(in, line)) ++lines;
      }
      add("convert --batch: one bad cell, row N - 8", o,
          " | output lines: " + std::to_string(lines) + " of " + std::to_string(largest + 1));
      std::error_code rm;
      fs::remove(o.out_path, rm);
    }
    {
      // Cut off in the middle of row N − 4 (its X cell), read from a pipe.
      const std::string command = "head -c " + std::to_string(xy_marks.second + 3) + " " + ShellQuote(largest_xy.string()) +
                                  " | " + ShellQuote(self) + " fit --xy - --method york";
      const Outcome o = Repeat(1, {"/bin/sh", "-c", command}, dir, "bad", true);
      add("fit --xy: cut off in row N - 4", o, "");
    }
    {
      // A line of f.long_line_bytes digits without a line end between good rows, from a pipe.
      const std::string command =
          "{ printf 'X,Y,uX,uY\\n1,2.1,0.1,0.1\\n2,3.9,0.1,0.1\\n'; head -c " + std::to_string(f.long_line_bytes) +
          " /dev/zero | tr '\\0' 7; printf '\\n3,6.2,0.1,0.1\\n4,8,0.1,0.1\\n'; } | " + ShellQuote(self) +
          " fit --xy - --method york";
      const Outcome o = Repeat(1, {"/bin/sh", "-c", command}, dir, "bad", true);
      const std::string text = ReadText(o.out_path, 256);
      add(FormatBytes(f.long_line_bytes) + " line without a line end", o,
          std::string(" | fit of the 4 good rows: ") + (text.rfind("method: york, n = 4,", 0) == 0 ? "printed" : "MISSING"));
    }
    section.tables.emplace_back("Bad input at scale (peak RSS of the pipeline's processes for the piped cases; "
                                "their time includes the generator):",
                                &bad);
  }
  std::error_code rm;
  fs::remove(largest_xy, rm);
  fs::remove(largest_settings, rm);
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace uphill::bench
