#include "bench/convert_benchmark.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "bench/synthetic_data.hpp"
#include "model/number_text.hpp"
#include "model/batch_convert.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "model/propagation.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;


// The lab's spheroid and Experiment 2 with plausible measurement uncertainties (metres): the
// Monte Carlo case of both sides (passed to the NumPy script, so the two cannot drift apart).
struct LabInput {
  const char* name;
  double value, u;
};
constexpr std::array<LabInput, 5> kLab = {{{"L", 1.165, 0.002},
                                           {"H", 0.300, 0.001},
                                           {"D", 0.045, 0.0005},
                                           {"a", 0.015875, 2e-5},
                                           {"b", 0.0254, 2e-5}}};
constexpr double kA = 0.015875, kB = 0.0254;

// --- accuracy against the 60-digit references ----------------------------------------------------

struct Accuracy {
  double max_rel = 0.0;
  int values = 0;
};

// θ, α, x_eq of the spheroid apparatus cases and the FIG. 5/6 sweeps on line rails, through the
// timed code path (ConvertApparatusBatch). Sweeps give angles: L = 1, H = tanθ, D = 2·tan(α/2).
Accuracy AgainstReferences(const std::string& path, VectorKernel kernel) {
  std::ifstream in(path);
  const nlohmann::json file = nlohmann::json::parse(in);
  auto ref = [](const nlohmann::json& v) {
    return v.is_number() ? v.get<double>() : std::strtod(v.get<std::string>().c_str(), nullptr);
  };
  Accuracy acc;
  for (const auto& c : file.at("cases")) {
    const bool rods = c.contains("rod_radius") && c.at("rod_radius").is_number() &&
                      c.at("rod_radius").get<double>() > 0;
    if (c.at("body").at("type") != "spheroid" || rods) continue;
    const double a = c.at("body").at("a"), b = c.at("body").at("b");
    std::vector<std::pair<std::array<double, 3>, const nlohmann::json*>> rows;
    if (c.at("rails").contains("apparatus")) {
      const auto& app = c.at("rails").at("apparatus");
      rows.push_back({{app.at("L"), app.at("H"), app.at("D")}, &c.at("outputs")});
    } else if (c.at("rails").contains("sweep")) {
      for (const auto& row : c.at("outputs").at("sweep"))
        rows.push_back({{1.0, std::tan(row.at("theta").get<double>()),
                         2 * std::tan(row.at("alpha").get<double>() / 2)},
                        &row});
    }
    for (const auto& [x, out] : rows) {
      double y[3];
      ConvertApparatusBatch(1, &x[0], &x[1], &x[2], a, b, &y[0], &y[1], &y[2], kernel);
      const char* keys[3] = {"theta", "alpha", "x_eq"};
      for (int k = 0; k < 3; ++k) {
        const double r = ref(out->at(keys[k]));
        acc.max_rel = std::max(acc.max_rel, std::abs(y[k] - r) / std::abs(r));
        ++acc.values;
      }
    }
  }
  return acc;
}

Table ResultTable() {
  return Table({{"workload", 46, true}, {"n", 9}, {"time/item", 10}, {"rate", 10}, {"peak RSS", 8}, {"accuracy", 0, true}});
}

std::string PerItem(double seconds, std::uint64_t n) {
  const double per = seconds / static_cast<double>(n);
  return per < 1e-6 ? Printf("%.2f ns", per * 1e9) : Printf("%.2f us", per * 1e6);
}

std::string Rate(double seconds, std::uint64_t n) {
  const double per_second = static_cast<double>(n) / seconds;
  if (per_second >= 1e9) return Printf("%.2f G/s", per_second / 1e9);
  if (per_second >= 1e6) return Printf("%.1f M/s", per_second / 1e6);
  return Printf("%.0f k/s", per_second / 1e3);
}

void Row(Table& table, const std::string& what, std::uint64_t n, const Measurement& m, const std::string& accuracy) {
  table.Add({what, Printf("%.3g", static_cast<double>(n)), PerItem(m.seconds, n), Rate(m.seconds, n),
             FormatBytes(m.peak_bytes), accuracy});
}

constexpr const char* kMethod =
    "One core, thread CPU time, best of the repeats. The conversion (L, H, D → θ, α, X of the lab spheroid, "
    "random configurations over the apparatus' range) runs the batch kernel (model/batch_convert.hpp: "
    "libmvec's AVX2 `atan` when the CPU has it, chosen at run time, else scalar); its accuracy is measured "
    "against the 60-digit references of tests/data/physics_reference.json through the same kernel. The "
    "Monte Carlo row is `Propagate` with five uncertain inputs and five outputs (the lab case below). "
    "NumPy (tools/bench/numpy_convert.py: the same formulas, arrays preallocated and written with out=) "
    "runs on the very same inputs; its accuracy is stated against uphill's results. \"peak RSS\": the "
    "process's peak resident memory over the row (input arrays included).";

}  // namespace

void RunConvertBenchmark(const ConvertBenchmarkOptions& f, std::ostream& out) {
  if (f.configurations < 1000) throw InputError("--configurations", "must be at least 1000");
  if (f.trials < 100) throw InputError("--trials", "must be at least 100");
  if (f.repeats < 1) throw InputError("--repeats", "must be at least 1");
  Section section = StartSection("convert", f.common.command, kMethod);
  const std::string reference = f.reference.empty() ? FindUpward("tests/data/physics_reference.json") : f.reference;
  const VectorKernel kernel = VectorKernel::kAuto;
  std::string lab = "Monte Carlo case (the lab spheroid, metres):";
  for (const LabInput& x : kLab) lab += std::string(" ") + x.name + " = " + Printf("%g", x.value) + " ± " + Printf("%g", x.u);
  out << "uphill bench convert: one core, thread CPU time, best of " << f.repeats << "; batch kernel "
      << VectorKernelName(kernel) << "\n" << lab << "\n\n";
  section.method += " " + lab + ".";
  Table table = ResultTable();
  table.Start(out);

  // Random configurations over the apparatus' range (metres).
  const std::size_t n = static_cast<std::size_t>(f.configurations);
  const ApparatusSettings settings = RandomApparatusSettings(n, f.seed);
  const std::vector<double>& L = settings.L;
  const std::vector<double>& H = settings.H;
  const std::vector<double>& D = settings.D;
  std::vector<double> theta(n), alpha(n), x_eq(n);
  auto convert = [&](VectorKernel k) {
    ConvertApparatusBatch(n, L.data(), H.data(), D.data(), kA, kB, theta.data(), alpha.data(), x_eq.data(), k);
  };
  auto accuracy = [&](VectorKernel k) {
    if (reference.empty()) return std::string("(tests/data/physics_reference.json not found)");
    const Accuracy acc = AgainstReferences(reference, k);
    return Printf("max rel err %.2g", acc.max_rel) + " vs 60-digit refs (theta, alpha, X: " +
           std::to_string(acc.values) + " values)";
  };
  convert(kernel);  // first touch of the output pages outside the timing
  const Measurement scalar_model = Measure(1, [&] { convert(VectorKernel::kScalar); });
  const Measurement batch = Measure(f.repeats, [&] { convert(kernel); });
  Row(table, std::string("convert L,H,D -> theta,alpha,X (") +
                 (VectorKernelAvailable(VectorKernel::kAvx2) ? "avx2" : "scalar") + ")",
      n, batch, accuracy(kernel));
  Row(table, "convert, scalar = the model (libm atan2)", n, scalar_model, accuracy(VectorKernel::kScalar));

  // Monte Carlo: the lab case, all five inputs uncertain.
  const auto rails = UncertainRails::Apparatus({kLab[0].value, kLab[0].u}, {kLab[1].value, kLab[1].u},
                                               {kLab[2].value, kLab[2].u});
  const auto body = UncertainBody::Spheroid({kLab[3].value, kLab[3].u}, {kLab[4].value, kLab[4].u});
  PropagationOptions options;
  options.trials = f.trials;
  options.seed = f.seed;
  PropagationResult mc;
  const Measurement monte_carlo = Measure(f.repeats, [&] { mc = Propagate(rails, body, {}, options); });
  double worst_fo = 0.0;
  for (const PropagatedValue* y : mc.Outputs())
    worst_fo = std::max(worst_fo, std::abs(y->u_monte_carlo / y->u_first_order - 1));
  const double se_u = 1.0 / std::sqrt(2.0 * static_cast<double>(mc.valid_trials - 1));
  Row(table, "Monte Carlo (Propagate), 5 inputs, 5 outputs", f.trials, monte_carlo,
      Printf("u to ±%.2f %% (1/sqrt(2M))", 100 * se_u) + Printf("; |u_MC/u_1st - 1| <= %.2f %%", 100 * worst_fo));

  // NumPy.
  std::string script = f.script.empty() ? FindUpward("tools/bench/numpy_convert.py") : f.script;
  const std::string why_not = PeerUnavailable(f.no_numpy ? "--no-numpy" : "", f.common.python, script,
                                              "tools/bench/numpy_convert.py not found (use --numpy-script)", "numpy");
  section.tables.emplace_back("", &table);
  if (!why_not.empty()) {
    out << "\nNumPy comparison skipped: " << why_not << "\n";
    section.notes.push_back("NumPy comparison skipped: " + why_not);
    Record(section, f.common.doc, f.common.no_doc, out);
    return;
  }
  const TemporaryDirectory temporary;
  const fs::path& dir = temporary.path();
  WriteFloat64(dir / "in.f64", {&L, &H, &D});
  std::string text;
  const std::string reps = " --repeats " + std::to_string(f.repeats);
  const std::string python = OneCorePython(f.common.python);
  if (!Capture(python + " " + ShellQuote(script) + " convert " + ShellQuote((dir / "in.f64").string()) + " " +
                   ShellQuote((dir / "out.f64").string()) + reps,
               &text))
    throw EnvironmentError("the NumPy script failed: " + script);
  const nlohmann::json np_convert = nlohmann::json::parse(text);
  for (const auto& [name, version] : np_convert.at("versions").items())
    section.versions.emplace_back(name, version.get<std::string>());
  const auto np = ReadFloat64(dir / "out.f64", 3, n);
  double diff = 0.0;
  const std::vector<double>* ours[3] = {&theta, &alpha, &x_eq};
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < n; ++i) diff = std::max(diff, std::abs((*ours[k])[i] - np[k][i]) / std::abs(np[k][i]));
  const Measurement np_batch{np_convert.at("seconds").get<double>(), np_convert.value("peak_bytes", std::uint64_t{0})};
  Row(table, "NumPy convert, same inputs", n, np_batch, Printf("max rel diff vs uphill %.2g", diff));

  nlohmann::json lab_case;
  for (const LabInput& x : kLab) lab_case[x.name] = {x.value, x.u};
  text.clear();
  if (!Capture(python + " " + ShellQuote(script) + " mc --trials " + std::to_string(f.trials) + " --seed " +
                   std::to_string(f.seed) + " --case " + ShellQuote(lab_case.dump()) + reps,
               &text))
    throw EnvironmentError("the NumPy script failed: " + script);
  const nlohmann::json np_mc = nlohmann::json::parse(text);
  double worst_np = 0.0;
  for (const PropagatedValue* y : mc.Outputs())
    worst_np = std::max(worst_np, std::abs(np_mc.at("stats").at(y->name).at("u").get<double>() / y->u_monte_carlo - 1));
  const Measurement np_monte_carlo{np_mc.at("seconds").get<double>(), np_mc.value("peak_bytes", std::uint64_t{0})};
  Row(table, "NumPy Monte Carlo, same case, own RNG", f.trials, np_monte_carlo,
      Printf("|u_NumPy/u_uphill - 1| <= %.2f %% (statistical)", 100 * worst_np));

  const double speed_convert = np_batch.seconds / batch.seconds, speed_mc = np_monte_carlo.seconds / monte_carlo.seconds;
  // Issue 14 sets no speed goal for the conversion (its 10x was measured against an older, slower
  // NumPy peer, and it asks to keep the kernel as it is); the agreement with NumPy is checked.
  const std::string goal_convert = "uphill vs NumPy per core: convert " + FormatRatio(speed_convert) +
                                   " (no speed goal; rel diff " + Printf("%.2g", diff) + ", goal <= 1e-14: " +
                                   (diff <= 1e-14 ? "met" : "NOT met") + ")";
  const std::string goal_mc = "uphill vs NumPy per core: Monte Carlo " + FormatRatio(speed_mc) + " (goal >= 10x): " +
                              (speed_mc >= 10 ? "met" : "NOT met");
  out << "\n" << goal_convert << "\n" << goal_mc << "\n";
  section.results = {goal_convert + "  ", goal_mc};
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace uphill::bench
