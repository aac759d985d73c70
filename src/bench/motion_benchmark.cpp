#include "bench/motion_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "oracle/motion_problems.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;

constexpr int kPoints = 200;

struct Row {
  std::string method, setting;
  double micros, error;
  double cpu_micros = -1;  // thread CPU time, where measured (uphill rows)
  std::uint64_t peak_bytes = 0;
};

double MaxRelError(const std::vector<double>& got, const std::vector<double>& ref) {
  double worst = 0;
  for (size_t i = 0; i < ref.size(); ++i) worst = std::max(worst, std::abs(got[i] / ref[i] - 1));
  return worst;
}

// Best of 5 repeats of ≥ 0.1 s each; microseconds per call (wall time), the thread CPU time of
// the same repeats in *cpu_micros (what a loaded, shared machine still measures fairly), and the
// peak RSS over them in *peak.
template <class Work>
double TimeIt(const Work& work, double* cpu_micros, std::uint64_t* peak) {
  const bool reset = ResetPeakResident();
  double best = 1e300, best_cpu = 1e300;
  for (int r = 0; r < 5; ++r) {
    long n = 0;
    const double start = WallSeconds(), cpu_start = CpuSeconds();
    double elapsed = 0;
    do {
      work();
      ++n;
      elapsed = WallSeconds() - start;
    } while (elapsed < 0.1);
    best = std::min(best, elapsed / n);
    best_cpu = std::min(best_cpu, (CpuSeconds() - cpu_start) / n);
  }
  *cpu_micros = best_cpu * 1e6;
  *peak = reset ? PeakResidentBytes() : 0;
  return best * 1e6;
}

constexpr const char* kMethod =
    "Three 200-point trajectories of a solid spheroid a = 20 mm, b = 32 mm on line rails θ = 1°, α = 30°, "
    "from x0 = 1.05·X (src/oracle/motion_problems.hpp): **release**, at rest, μ = 0, the times at 200 positions "
    "equally spaced up to 0.99·x_max; **turns**, thrown toward O at half the speed that would carry it over X: "
    "the first times at 100 positions from the turning point to 90 % of the way back to x0 and 100 from x0 to 0.99·x_max; "
    "**comes to rest**, μ = half the slope at x0, thrown toward O so that it stops inside the rest band: the "
    "times at 200 positions from the rest point to 90 % of the way to x0. Error: the largest relative error of the 200 times "
    "against src/oracle's 50-digit references (the energy balance per leg by Gauss–Kronrod 61 in "
    "cpp_bin_float_50 at 1e-35, turning points in 50 digits). Time: wall time per trajectory (the Motion built "
    "and the 200 times asked), one core, best of 5 repeats of ≥ 0.1 s each; the uphill rows also give the "
    "thread CPU time of the same runs, which a shared, loaded machine still measures fairly. Peers "
    "(tools/bench/motion_peers.py), on every trajectory: solve_ivp (RK45, DOP853, LSODA) on the same equation "
    "of motion with events and dense output; on the release also scipy.integrate.quad, solve_ivp on dt/dw and a "
    "NumPy Gauss–Legendre rule. \"peak RSS\": the process's peak resident memory over the row. The goal line "
    "compares, at each accuracy 1e-6, 1e-7, …, 1e-12, the fastest uphill equation-of-motion row reaching it "
    "with the fastest SciPy solve_ivp row reaching it (wall times).";

bool IsSolveIvp(const std::string& method) { return method.rfind("scipy solve_ivp", 0) == 0; }
bool IsUphillOde(const std::string& method) { return method.rfind("uphill ode", 0) == 0; }

// "≥ 10× SciPy's best solve_ivp at equal accuracy from 1e-6 to 1e-12": the smallest ratio over
// the accuracy levels, and the level where it occurs.
std::string GoalLine(const std::string& name, const std::vector<Row>& rows, bool* met) {
  double worst = 1e300, worst_level = 0;
  std::string missing;
  for (int e = 6; e <= 12; ++e) {
    const double level = std::pow(10.0, -e);
    double ours = 1e300, peer = 1e300;
    for (const Row& r : rows) {
      if (r.error > level) continue;
      if (IsUphillOde(r.method)) ours = std::min(ours, r.micros);
      if (IsSolveIvp(r.method)) peer = std::min(peer, r.micros);
    }
    if (ours == 1e300) {
      missing += " uphill misses 1e-" + std::to_string(e) + ";";
      *met = false;
      continue;
    }
    if (peer == 1e300) continue;  // SciPy does not reach this accuracy: no ratio
    if (peer / ours < worst) worst = peer / ours, worst_level = level;
  }
  char line[320];
  if (worst == 1e300)
    std::snprintf(line, sizeof line, "%s: no SciPy solve_ivp row in this run to compare with.%s", name.c_str(),
                  missing.c_str());
  else
    std::snprintf(line, sizeof line, "%s: smallest ratio SciPy solve_ivp / uphill ode at equal accuracy "
                  "(1e-6 … 1e-12) %.1fx, at %.0e;%s", name.c_str(), worst, worst_level, missing.c_str());
  if (worst < 10.0) *met = false;
  return line;
}

void RenderWorkPrecision(const std::string& file, const std::string& title, const std::vector<Row>& rows,
                         const std::string& out_dir) {
  std::string data;
  std::vector<std::string> methods;
  for (const Row& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  std::string plot =
      "set logscale xy\nset xlabel 'max relative error of the 200 times'\nset ylabel 'time per trajectory [us]'\n"
      "set key outside below font ',9'\nset format x '10^{%L}'\nset grid\nplot ";
  for (size_t k = 0; k < methods.size(); ++k) {
    data += "# " + methods[k] + "\n# error  time_us\n";
    for (const Row& r : rows)
      if (r.method == methods[k]) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.6e %.6e\n", std::max(r.error, 1e-17), r.micros);
        data += buf;
      }
    data += "\n\n";
    plot += std::string(k ? ", " : "") + "'" + file + ".dat' index " + std::to_string(k) +
            " with linespoints title '" + methods[k] + "' noenhanced";
  }
  plot += "\n";
  RenderFigure({file, "Work-precision of the motion methods: " + title,
                "Time per 200-point trajectory against the largest relative error (spheroid 20x32 mm, theta 1 deg, "
                "alpha 30 deg, from 1.05 X; " + title + ").",
                data, plot},
               out_dir);
}

// The SciPy/NumPy rows of one problem ("" and the rows appended, or why they are missing).
std::string RunPeers(const MotionBenchmarkOptions& f, const oracle::MotionProblem& p, const std::string& script,
                     Section* section, std::vector<Row>* rows) {
  const Rails& rails = p.scene.rails();
  fs::create_directories(f.out);
  std::string file = p.name;
  std::replace(file.begin(), file.end(), ' ', '_');
  const fs::path problem = fs::path(f.out) / ("motion_problem_" + file + ".txt");
  {
    std::ofstream out(problem);
    out.precision(17);
    out << p.a << " " << p.b << " " << rails.tan_theta << " " << rails.tan_half_alpha << " " << p.g << " " << p.x0
        << " " << p.v0 << " " << p.mu << "\n";
    for (size_t i = 0; i < p.xs.size(); ++i) out << p.xs[i] << " " << p.reference.times[i] << "\n";
  }
  std::string text;
  if (!Capture(OneCorePython(f.common.python) + " " + ShellQuote(script) + " " + ShellQuote(problem.string()), &text))
    return "the peer script failed";
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    // versions|{JSON}, or method|setting|micros|error|peak_bytes
    std::vector<std::string> parts;
    std::stringstream ss(line);
    std::string part;
    while (std::getline(ss, part, '|')) parts.push_back(part);
    if (parts.size() == 2 && parts[0] == "versions") {
      const nlohmann::json versions = nlohmann::json::parse(parts[1]);  // alive through the loop
      for (const auto& [name, version] : versions.items()) {
        const std::pair<std::string, std::string> entry(name, version.get<std::string>());
        // Once, not per trajectory.
        if (std::find(section->versions.begin(), section->versions.end(), entry) == section->versions.end())
          section->versions.push_back(entry);
      }
    } else if (parts.size() == 5) {
      Row row{parts[0], parts[1], std::stod(parts[2]), std::stod(parts[3])};
      row.peak_bytes = std::stoull(parts[4]);
      rows->push_back(row);
    }
  }
  return "";
}

}  // namespace

void RunMotionBenchmark(const MotionBenchmarkOptions& f, std::ostream& out) {
  Section section = StartSection("motion", f.common.command, kMethod);
  const std::string script = f.script.empty() ? FindUpward("tools/bench/motion_peers.py") : f.script;
  std::string why_not = PeerUnavailable(f.no_python ? "--no-python" : f.release_only ? "--release-only" : "",
                                        f.common.python, script, "tools/bench/motion_peers.py not found (use --script)",
                                        "scipy");
  out << "uphill bench motion: spheroid a = 20 mm, b = 32 mm, theta = 1 deg, alpha = 30 deg, from 1.05 X;\n"
         "three trajectories of 200 positions (release, turns, comes to rest).\n"
         "Error: max relative error of the 200 times against cpp_bin_float_50 references.\n"
         "Time: wall time per 200-point trajectory, one core, best of 5.\n";
  // Tables live until the section is recorded.
  std::vector<std::unique_ptr<Table>> tables;
  std::vector<std::string> goals;
  bool met = true;
  for (oracle::MotionProblemKind kind : {oracle::MotionProblemKind::kRelease, oracle::MotionProblemKind::kTurning,
                                         oracle::MotionProblemKind::kComesToRest}) {
    if (f.release_only && kind != oracle::MotionProblemKind::kRelease) continue;
    const oracle::MotionProblem p = oracle::MakeMotionProblem(kind, kPoints);
    const std::vector<double>& ref = p.reference.times;
    char intro[256];
    std::snprintf(intro, sizeof intro, "\n%s: x0 = %.6f mm, v0 = %.6g mm/s, mu = %.6g; last event at t = %.6f s\n",
                  p.name.c_str(), p.x0 * 1e3, p.v0 * 1e3, p.mu, p.reference.events.back().t);
    out << intro << std::flush;
    std::vector<Row> rows;
    std::vector<double> got(p.xs.size());
    for (int e = 3; e <= 13 && !f.release_only; ++e) {
      const double tol = std::pow(10.0, -e);
      for (MotionMethod m : {MotionMethod::kQuadrature, MotionMethod::kOde}) {
        if (m == MotionMethod::kQuadrature && (p.mu != 0 || e % 2 == 0)) continue;
        MotionOptions o;
        o.method = m;
        o.tolerance = tol;
        o.g = p.g;
        o.v0 = p.v0;
        o.mu = p.mu;
        auto work = [&] {
          const Motion motion(p.scene, p.x0, o);
          for (size_t i = 0; i < p.xs.size(); ++i) got[i] = motion.TimeAt(p.xs[i]);
        };
        work();
        Row row{m == MotionMethod::kOde ? "uphill ode (Odeint Dopri5, dense output, TimeAt)"
                                        : "uphill quadrature (GK31 adaptive, TimeAt)",
                "tol 1e-" + std::to_string(e), 0, MaxRelError(got, ref)};
        row.micros = TimeIt(work, &row.cpu_micros, &row.peak_bytes);
        rows.push_back(row);
      }
    }
    if (kind == oracle::MotionProblemKind::kRelease) {
      // The fast path: node count from the a-priori estimate (per tolerance), and fixed counts.
      std::vector<VectorKernel> kernels = {VectorKernel::kScalar};
      if (VectorKernelAvailable(VectorKernel::kAvx2)) kernels.insert(kernels.begin(), VectorKernel::kAvx2);
      for (VectorKernel kernel : kernels) {
        const std::string name = std::string("uphill ReleaseTimes, ") + VectorKernelName(kernel);
        auto add = [&](const ReleaseTimesOptions& o, const std::string& setting) {
          auto work = [&] { ReleaseTimes(p.scene, p.x0, p.xs, got, o); };
          work();
          Row row{o.nodes ? name + ", fixed nodes" : name, setting, 0, MaxRelError(got, ref)};
          row.micros = TimeIt(work, &row.cpu_micros, &row.peak_bytes);
          rows.push_back(row);
        };
        for (int e = 3; e <= 15; e += (e < 11 ? 2 : 1)) {
          ReleaseTimesOptions o;
          o.g = p.g;
          o.kernel = kernel;
          o.tolerance = std::pow(10.0, -e);
          add(o, "tol 1e-" + std::to_string(e));
        }
        for (int n : {3, 4, 5, 6}) {
          ReleaseTimesOptions o;
          o.g = p.g;
          o.kernel = kernel;
          o.nodes = n;
          add(o, std::to_string(n) + " nodes");
        }
      }
    }
    if (why_not.empty()) why_not = RunPeers(f, p, script, &section, &rows);
    auto table = std::make_unique<Table>(std::vector<Table::Column>{{"method", 60, true}, {"setting", 12, true},
                                                                    {"time/traj", 11}, {"max rel err", 11},
                                                                    {"(cpu time)", 10}, {"peak RSS", 8}});
    table->Start(out);
    for (const Row& r : rows) {
      char error[32];
      std::snprintf(error, sizeof error, "%.2e", r.error);
      table->Add({r.method, r.setting, FormatSeconds(r.micros * 1e-6), error,
                  r.cpu_micros >= 0 ? FormatSeconds(r.cpu_micros * 1e-6) : "", FormatBytes(r.peak_bytes)});
    }
    section.tables.emplace_back("Trajectory: " + p.name, table.get());
    tables.push_back(std::move(table));
    if (!f.release_only) goals.push_back(GoalLine(p.name, rows, &met));
    if (kind == oracle::MotionProblemKind::kRelease) {
      double best = 1e300, best_cpu = 1e300;
      for (const Row& r : rows)
        if (r.method.rfind("uphill", 0) == 0 && r.error <= 1e-12) {
          best = std::min(best, r.micros);
          if (r.cpu_micros >= 0) best_cpu = std::min(best_cpu, r.cpu_micros);
        }
      char goal[256];
      std::snprintf(goal, sizeof goal,
                    "Goal (release): <= 1e-12 in <= 10 us per trajectory. Fastest uphill row at <= 1e-12: %.1f us "
                    "wall, %.1f us thread CPU time (%s).",
                    best, best_cpu,
                    best <= 10.0 ? "met" : best_cpu <= 10.0 ? "met in CPU time only: the machine is loaded" : "not met");
      out << "\n" << goal << "\n";
      section.results.push_back(goal);
    }
    std::string file = "work_precision_motion";
    if (kind != oracle::MotionProblemKind::kRelease) file += "_" + std::string(kind == oracle::MotionProblemKind::kTurning ? "turns" : "rest");
    fs::create_directories(f.out);
    RenderWorkPrecision(file, p.name, rows, f.out);
    out << "figure: " << f.out << "/" << file << ".{svg,png}\n";
  }
  if (!why_not.empty()) {
    out << "\nSciPy/NumPy comparison skipped: " << why_not << "\n";
    section.notes.push_back("SciPy/NumPy comparison skipped: " + why_not);
  }
  if (!f.release_only) {
    std::string goal = "Goal: uphill's equation of motion >= 10x SciPy's best solve_ivp at equal accuracy from 1e-6 to "
                       "1e-12 on each trajectory (" + std::string(why_not.empty() ? (met ? "met" : "not met") : "not measured") + ").";
    out << "\n" << goal << "\n";
    section.results.push_back(goal);
    for (const std::string& g : goals) {
      out << "  " << g << "\n";
      section.results.push_back(g);
    }
  }
  Record(section, f.common.doc, f.common.no_doc, out);
}

}  // namespace uphill::bench
