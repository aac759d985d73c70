// `uphill bench convert`: throughput of the conversion and of the Monte Carlo propagation on one
// core, each row with the accuracy it reached, and the same work in NumPy when /usr/bin/python3
// has it (tools/bench/numpy_convert.py, run as a subprocess; inputs and outputs go through raw float64
// files in a temporary directory so that both sides compute on the very same numbers).
//
// Times are thread CPU time (CLOCK_THREAD_CPUTIME_ID here, time.thread_time() in Python), best
// of --repeats: the throughput of one core, and not skewed by other load on the machine.

#include <algorithm>
#include <array>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/uniform_real_distribution.hpp>
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

#include "bench_support.hpp"
#include "commands.hpp"
#include "model/number_text.hpp"
#include "model/batch_convert.hpp"
#include "model/input_error.hpp"
#include "model/propagation.hpp"

namespace uphill::cli {
namespace {

namespace fs = std::filesystem;

struct BenchFlags {
  std::uint64_t configurations = 10'000'000;
  std::uint64_t trials = 1'000'000;
  std::uint64_t seed = 1;
  int repeats = 3;
  std::string python = "/usr/bin/python3";
  std::string script;     // default: tools/bench/numpy_convert.py found upward
  std::string reference;  // default: tests/data/physics_reference.json found upward
  bool no_numpy = false;
};

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
Accuracy AgainstReferences(const std::string& path, BatchKernel kernel) {
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

// --- table -----------------------------------------------------------------------------------


std::string Rate(double per_second) {
  if (per_second >= 1e9) return Printf("%.2f G/s", per_second / 1e9);
  if (per_second >= 1e6) return Printf("%.1f M/s", per_second / 1e6);
  return Printf("%.0f k/s", per_second / 1e3);
}

void Row(const std::string& what, std::uint64_t n, double seconds, const std::string& accuracy) {
  const double per = seconds / static_cast<double>(n);
  std::printf("%-44s %9.3g %10s %11s  %s\n", what.c_str(), static_cast<double>(n),
              (per < 1e-6 ? Printf("%.2f ns", per * 1e9) : Printf("%.2f us", per * 1e6)).c_str(),
              Rate(1.0 / per).c_str(), accuracy.c_str());
}

void Run(const BenchFlags& f) {
  if (f.configurations < 1000) throw InputError("--configurations", "must be at least 1000");
  if (f.trials < 100) throw InputError("--trials", "must be at least 100");
  if (f.repeats < 1) throw InputError("--repeats", "must be at least 1");
  const std::string reference = f.reference.empty() ? bench::FindUpward("tests/data/physics_reference.json") : f.reference;
  const BatchKernel kernel = BatchKernel::kAuto;
  std::printf("uphill bench convert: one core, thread CPU time, best of %d; batch kernel %s\n",
              f.repeats, BatchKernelName(kernel));
  std::printf("Monte Carlo case (the lab spheroid, metres):");
  for (const LabInput& x : kLab) std::printf(" %s = %g ± %g", x.name, x.value, x.u);
  std::printf("\n\n");
  std::printf("%-44s %9s %10s %11s  %s\n", "workload", "n", "time/item", "rate", "accuracy");

  // Random configurations over the apparatus' range (metres).
  const std::size_t n = static_cast<std::size_t>(f.configurations);
  std::vector<double> L(n), H(n), D(n);
  {
    boost::random::mt19937_64 engine(f.seed);
    boost::random::uniform_real_distribution<double> uL(0.5, 2.0), uH(0.05, 0.5), uD(0.02, 0.25);
    for (std::size_t i = 0; i < n; ++i) {
      L[i] = uL(engine);
      H[i] = uH(engine);
      D[i] = uD(engine);
    }
  }
  std::vector<double> theta(n), alpha(n), x_eq(n);
  auto convert = [&](BatchKernel k) {
    ConvertApparatusBatch(n, L.data(), H.data(), D.data(), kA, kB, theta.data(), alpha.data(),
                          x_eq.data(), k);
  };
  auto accuracy = [&](BatchKernel k) {
    if (reference.empty()) return std::string("(tests/data/physics_reference.json not found)");
    const Accuracy acc = AgainstReferences(reference, k);
    return Printf("max rel err %.2g", acc.max_rel) + " vs 60-digit refs (theta, alpha, X: " +
           std::to_string(acc.values) + " values)";
  };
  convert(kernel);  // first touch of the output pages outside the timing
  const double t_scalar_model = bench::BestOf(1, [&] { convert(BatchKernel::kScalar); });
  const double t_convert = bench::BestOf(f.repeats, [&] { convert(kernel); });
  Row(std::string("convert L,H,D -> theta,alpha,X (") +
          (BatchKernelAvailable(BatchKernel::kAvx2) ? "avx2" : "scalar") + ")",
      n, t_convert, accuracy(kernel));
  Row("convert, scalar = the model (libm atan2)", n, t_scalar_model, accuracy(BatchKernel::kScalar));

  // Monte Carlo: the lab case, all five inputs uncertain.
  const auto rails = UncertainRails::Apparatus({kLab[0].value, kLab[0].u}, {kLab[1].value, kLab[1].u},
                                               {kLab[2].value, kLab[2].u});
  const auto body = UncertainBody::Spheroid({kLab[3].value, kLab[3].u}, {kLab[4].value, kLab[4].u});
  PropagationOptions options;
  options.trials = f.trials;
  options.seed = f.seed;
  PropagationResult mc;
  const double t_mc = bench::BestOf(f.repeats, [&] { mc = Propagate(rails, body, {}, options); });
  double worst_fo = 0.0;
  for (const PropagatedValue* y : mc.Outputs())
    worst_fo = std::max(worst_fo, std::abs(y->u_monte_carlo / y->u_first_order - 1));
  const double se_u = 1.0 / std::sqrt(2.0 * static_cast<double>(mc.valid_trials - 1));
  Row("Monte Carlo (Propagate), 5 inputs, 5 outputs", f.trials, t_mc,
      Printf("u to ±%.2f %% (1/sqrt(2M))", 100 * se_u) + Printf("; |u_MC/u_1st - 1| <= %.2f %%", 100 * worst_fo));

  // NumPy.
  std::string script = f.script.empty() ? bench::FindUpward("tools/bench/numpy_convert.py") : f.script;
  std::string why_not;
  if (f.no_numpy) why_not = "--no-numpy";
  else if (access(f.python.c_str(), X_OK) != 0) why_not = f.python + " not found";
  else if (script.empty()) why_not = "tools/bench/numpy_convert.py not found (use --numpy-script)";
  else if (std::system((bench::ShellQuote(f.python) + " -c 'import numpy' > /dev/null 2>&1").c_str()) != 0)
    why_not = f.python + " has no NumPy (bash scripts/install-deps.sh --bench)";
  if (!why_not.empty()) {
    std::printf("\nNumPy comparison skipped: %s\n", why_not.c_str());
    return;
  }
  const bench::TemporaryDirectory temporary;
  const fs::path& dir = temporary.path();
  bench::WriteFloat64(dir / "in.f64", {&L, &H, &D});
  std::string out;
  const std::string reps = " --repeats " + std::to_string(f.repeats);
  const std::string python = bench::OneCorePython(f.python);
  if (!bench::Capture(python + " " + bench::ShellQuote(script) + " convert " +
                          bench::ShellQuote((dir / "in.f64").string()) + " " +
                          bench::ShellQuote((dir / "out.f64").string()) + reps,
                      &out))
    throw std::runtime_error("the NumPy script failed: " + script);
  const nlohmann::json np_convert = nlohmann::json::parse(out);
  const auto np = bench::ReadFloat64(dir / "out.f64", 3, n);
  double diff = 0.0;
  const std::vector<double>* ours[3] = {&theta, &alpha, &x_eq};
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < n; ++i)
      diff = std::max(diff, std::abs((*ours[k])[i] - np[k][i]) / std::abs(np[k][i]));
  const double t_np = np_convert.at("seconds");
  Row("NumPy " + np_convert.at("numpy").get<std::string>() + " convert, same inputs", n, t_np,
      Printf("max rel diff vs uphill %.2g", diff));

  nlohmann::json lab_case;
  for (const LabInput& x : kLab) lab_case[x.name] = {x.value, x.u};
  out.clear();
  if (!bench::Capture(python + " " + bench::ShellQuote(script) + " mc --trials " + std::to_string(f.trials) +
                   " --seed " + std::to_string(f.seed) + " --case " + bench::ShellQuote(lab_case.dump()) + reps,
               &out))
    throw std::runtime_error("the NumPy script failed: " + script);
  const nlohmann::json np_mc = nlohmann::json::parse(out);
  double worst_np = 0.0;
  for (const PropagatedValue* y : mc.Outputs())
    worst_np = std::max(worst_np, std::abs(np_mc.at("stats").at(y->name).at("u").get<double>() / y->u_monte_carlo - 1));
  const double t_np_mc = np_mc.at("seconds");
  Row("NumPy Monte Carlo, same case, own RNG", f.trials, t_np_mc,
      Printf("|u_NumPy/u_uphill - 1| <= %.2f %% (statistical)", 100 * worst_np));

  const double speed_convert = t_np / t_convert, speed_mc = t_np_mc / t_mc;
  std::printf("\nuphill vs NumPy per core: convert %.1fx (goal >= 10x, rel diff %.2g, goal <= 1e-14): %s\n",
              speed_convert, diff, speed_convert >= 10 && diff <= 1e-14 ? "met" : "NOT met");
  std::printf("                          Monte Carlo %.1fx (goal >= 10x): %s\n", speed_mc,
              speed_mc >= 10 ? "met" : "NOT met");
  std::printf("NumPy per configuration %.1f ns, per Monte Carlo trial %.1f ns\n", 1e9 * t_np / static_cast<double>(n),
              1e9 * t_np_mc / static_cast<double>(f.trials));
}

}  // namespace

void AddBenchConvert(CLI::App& bench) {
  auto flags = std::make_shared<BenchFlags>();
  CLI::App* cmd = bench.add_subcommand(
      "convert", "Conversion and Monte Carlo throughput per core, with accuracy, against NumPy");
  cmd->add_option("--configurations", flags->configurations, "random configurations to convert")
      ->capture_default_str();
  cmd->add_option("--trials", flags->trials, "Monte Carlo trials")->capture_default_str();
  cmd->add_option("--seed", flags->seed, "seed of the configurations and of the Monte Carlo")
      ->capture_default_str();
  cmd->add_option("--repeats", flags->repeats, "timed repeats per row (the best counts)")
      ->capture_default_str();
  cmd->add_option("--python", flags->python, "Python with NumPy for the comparison")->capture_default_str();
  cmd->add_option("--numpy-script", flags->script, "path of tools/bench/numpy_convert.py");
  cmd->add_option("--reference", flags->reference, "path of tests/data/physics_reference.json");
  cmd->add_flag("--no-numpy", flags->no_numpy, "skip the NumPy comparison");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
