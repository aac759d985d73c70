#include "bench/python_benchmark.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "bench/synthetic_data.hpp"
#include "fit/york_line.hpp"
#include "model/batch_convert.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "model/vector_kernel.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;

constexpr double kA = 0.015875, kB = 0.0254;  // the lab spheroid, m

constexpr const char* kMethod =
    "One core, thread CPU time, best of the repeats, the same clock on both sides. The C++ rows call the "
    "library's kernel directly on data already in memory, outputs preallocated: the batch conversion "
    "(ConvertApparatusBatch: L, H, D → θ, α, X of the lab spheroid, random settings over the apparatus' range) "
    "and York's fit (FitErrorsInVariables on rows Y = 1 + 2t + u(Y)·n, X = t + u(X)·n, as `uphill bench fit`). "
    "The Python rows run in one /usr/bin/python3 process (tools/bench/python_module.py) on the very same "
    "doubles: `uphill.convert_apparatus` writing into preallocated arrays (`theta=`, `alpha=`, `x_eq=`) and "
    "allocating its results (fresh pages, as a plain call does), `uphill.fit_york`, and NumPy's conversion "
    "(numpy_convert.py) and York iteration (fit_peers.py). \"vs C++\" is the Python call's time over the "
    "kernel's: the cost of the binding (argument checks, the domain check of every element, the GIL, and for "
    "the fit the copy into the library's rows). Accuracy: the module's results against the C++ kernel's, "
    "element by element (the module runs that kernel, so they must be identical), NumPy's against the "
    "module's. \"peak RSS\": the process's peak resident memory over the row.";

Table ResultTable() {
  return Table({{"workload", 52, true}, {"n", 9}, {"time", 10}, {"vs C++", 8}, {"peak RSS", 9}, {"accuracy", 0, true}});
}

std::string Overhead(double seconds, double kernel) { return Printf("%+.1f %%", 100.0 * (seconds / kernel - 1.0)); }

// Elements of a and b that differ in their bits.
std::size_t BitDifferences(const std::vector<double>& a, const std::vector<double>& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += std::memcmp(&a[i], &b[i], sizeof(double)) != 0;
  return differ;
}

std::string ModuleDirectory(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  if (fs::is_directory(UPHILL_PYTHON_MODULE_DIR, ec))
    for (const auto& entry : fs::directory_iterator(UPHILL_PYTHON_MODULE_DIR, ec))
      if (entry.path().filename().string().rfind("uphill.", 0) == 0 && entry.path().extension() == ".so")
        return UPHILL_PYTHON_MODULE_DIR;
  return "";  // an installed program: the module is where Python finds it
}

}  // namespace

void RunPythonBenchmark(const PythonBenchmarkOptions& f, std::ostream& out) {
  if (f.elements < 1000) throw InputError("--elements", "must be at least 1000");
  if (f.repeats < 1) throw InputError("--repeats", "must be at least 1");
  Section section = StartSection("python", f.common.command, kMethod);
  const std::string script = f.script.empty() ? FindUpward("tools/bench/python_module.py") : f.script;
  const std::string module_dir = ModuleDirectory(f.module_dir);
  const std::string python_path = "PYTHONPATH=" + ShellQuote(module_dir + (module_dir.empty() ? "" : ":") +
                                                             fs::path(script).parent_path().string()) + " ";
  std::string why_not = PeerUnavailable("", f.common.python, script,
                                        "tools/bench/python_module.py not found (use --script)", "numpy");
  if (why_not.empty() &&
      std::system((python_path + ShellQuote(f.common.python) + " -c 'import uphill' > /dev/null 2>&1").c_str()) != 0)
    why_not = f.common.python + " cannot import uphill (build it: UPHILL_PYTHON=ON, or give --module-dir)";
  if (!why_not.empty()) throw std::runtime_error("uphill bench python: " + why_not);

  out << "uphill bench python: one core, thread CPU time, best of " << f.repeats << "; batch kernel "
      << VectorKernelName() << "\n\n";
  Table table = ResultTable();
  table.Start(out);
  const std::size_t n = static_cast<std::size_t>(f.elements);

  // The conversion's inputs, as `uphill bench convert` draws them (metres).
  const ApparatusSettings settings = RandomApparatusSettings(n, f.seed);
  const std::vector<double>& L = settings.L;
  const std::vector<double>& H = settings.H;
  const std::vector<double>& D = settings.D;
  std::vector<double> theta(n), alpha(n), x_eq(n);
  auto convert = [&] {
    ConvertApparatusBatch(n, L.data(), H.data(), D.data(), kA, kB, theta.data(), alpha.data(), x_eq.data());
  };
  convert();  // first touch of the output pages outside the timing
  const Measurement kernel = Measure(f.repeats, convert);
  table.Add({"C++ kernel: ConvertApparatusBatch", Printf("%.3g", double(n)), FormatSeconds(kernel.seconds), "",
             FormatBytes(kernel.peak_bytes), "the reference of the rows below"});

  // York's rows, as `uphill bench fit` draws them (Y = 1 + 2t + u(Y)·n, X = t + u(X)·n, t on [0, 10]).
  const LineData line = StraightLine(n, f.seed + 1, 0.0, 10.0, 1.0);
  FitReport york;
  const Measurement york_kernel = Measure(f.repeats, [&] { york = FitErrorsInVariables(line); });
  table.Add({"C++ kernel: FitErrorsInVariables (York)", Printf("%.3g", double(n)), FormatSeconds(york_kernel.seconds),
             "", FormatBytes(york_kernel.peak_bytes), "the reference of the rows below"});

  const TemporaryDirectory temporary;
  const fs::path& dir = temporary.path();
  WriteFloat64(dir / "convert.f64", {&L, &H, &D});
  WriteFloat64(dir / "york.f64", {&line.x, &line.y, &line.u_x, &line.u_y});
  std::string text;
  if (!Capture(python_path + OneCorePython(f.common.python) + " " + ShellQuote(script) + " " +
                   ShellQuote((dir / "convert.f64").string()) + " " + ShellQuote((dir / "convert_out.f64").string()) +
                   " " + ShellQuote((dir / "york.f64").string()) + Printf(" --a %.17g", kA) + Printf(" --b %.17g", kB) +
                   " --repeats " + std::to_string(f.repeats),
               &text))
    throw std::runtime_error("the Python side failed: " + script);
  const nlohmann::json py = nlohmann::json::parse(text);
  for (const auto& [name, version] : py.at("versions").items()) section.versions.emplace_back(name, version.get<std::string>());
  const auto module_out = ReadFloat64(dir / "convert_out.f64", 3, n);
  const std::size_t differ =
      BitDifferences(module_out[0], theta) + BitDifferences(module_out[1], alpha) + BitDifferences(module_out[2], x_eq);
  const std::string identical = differ == 0 ? "identical to the C++ kernel (3n values, bit for bit)"
                                            : std::to_string(differ) + " of 3n values differ from the C++ kernel";
  auto row = [&](const char* key) {
    const auto& r = py.at("rows").at(key);
    return Measurement{r.at("seconds").get<double>(), r.value("peak_bytes", std::uint64_t{0})};
  };
  const Measurement out_call = row("convert_out"), new_call = row("convert_new"), np_convert = row("numpy_convert");
  table.Add({"Python: uphill.convert_apparatus(..., out arrays)", Printf("%.3g", double(n)),
             FormatSeconds(out_call.seconds), Overhead(out_call.seconds, kernel.seconds), FormatBytes(out_call.peak_bytes),
             identical});
  table.Add({"Python: uphill.convert_apparatus(...) new arrays", Printf("%.3g", double(n)),
             FormatSeconds(new_call.seconds), Overhead(new_call.seconds, kernel.seconds), FormatBytes(new_call.peak_bytes),
             "the same numbers; includes faulting in " + FormatBytes(3 * sizeof(double) * n) + " of fresh result pages"});
  table.Add({"Python: NumPy conversion (out= arrays)", Printf("%.3g", double(n)), FormatSeconds(np_convert.seconds),
             Overhead(np_convert.seconds, kernel.seconds), FormatBytes(np_convert.peak_bytes),
             "max rel diff vs the module " +
                 FormatDeviation(py.at("rows").at("numpy_convert").at("max_rel_diff_vs_module").get<double>())});
  const Measurement py_york = row("york"), np_york = row("numpy_york");
  const auto& yr = py.at("rows").at("york");
  const bool york_same = yr.at("slope").get<double>() == york.slope() && yr.at("intercept").get<double>() == york.intercept();
  table.Add({"Python: uphill.fit_york", Printf("%.3g", double(n)), FormatSeconds(py_york.seconds),
             Overhead(py_york.seconds, york_kernel.seconds), FormatBytes(py_york.peak_bytes),
             york_same ? "slope, intercept identical to the C++ fit" : "slope/intercept DIFFER from the C++ fit"});
  const auto& nr = py.at("rows").at("numpy_york");
  table.Add({"Python: NumPy York iteration", Printf("%.3g", double(n)), FormatSeconds(np_york.seconds),
             Overhead(np_york.seconds, york_kernel.seconds), FormatBytes(np_york.peak_bytes),
             "slope rel diff vs uphill " + FormatDeviation(std::abs(nr.at("slope").get<double>() / york.slope() - 1))});
  section.tables.emplace_back("", &table);

  const double overhead = out_call.seconds / kernel.seconds - 1.0;
  const std::string goal = "Python call on " + Printf("%.3g", double(n)) + " elements: C++ kernel " +
                           Printf("%+.1f %%", 100 * overhead) + " (goal <= +10 %, results identical): " +
                           (overhead <= 0.10 && differ == 0 ? "met" : "NOT met");
  out << "\n" << goal << "\n";
  section.results = {goal};
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace uphill::bench
