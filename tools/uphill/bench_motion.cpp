// `uphill bench motion`: work–precision of the motion methods (src/motion) on one trajectory,
// against SciPy and NumPy when /usr/bin/python3 has them (tools/bench/motion_peers.py).
//
// Problem: spheroid a = 20 mm, b = 32 mm (b/a = 1.6, the paper's FIG. 4 family) on line rails
// θ = 1°, α = 30°, released from rest at 1.05·X; the times at 200 positions equally spaced from
// x0 to 0.99·x_max (x_i = x0 + (0.99·x_max − x0)·i/200, i = 1…200). Error: the largest relative
// error of the 200 times against a reference computed with boost::multiprecision::
// cpp_bin_float_50 (the same smooth integrand in w, ψ − ψ0 = u0·cosh w, by Gauss–Kronrod 61 at
// 1e-35 on each interval; its own error is far below 1e-20). Time: wall time per 200-point
// trajectory on one core (best of repeats, each repeat ≥ 0.1 s of work).
#include <unistd.h>

#include <algorithm>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "commands.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill::cli {
namespace {

namespace fs = std::filesystem;
using Big = boost::multiprecision::cpp_bin_float_50;

constexpr double kA = 0.020, kB = 0.032, kThetaDeg = 1.0, kAlphaDeg = 30.0, kG = 9.80665;
constexpr int kPoints = 200;

struct Flags {
  std::string out = "bench-motion";
  std::string python = "/usr/bin/python3";
  std::string script;
  bool no_python = false;
  bool release_only = false;  // only the ReleaseTimes rows (no Motion rows, no peers)
};

struct Row {
  std::string method, setting;
  double micros, error;
  double cpu_micros = -1;  // thread CPU time, where measured (uphill rows)
};

std::string FindUpward(const std::string& rel) {
  fs::path dir = fs::current_path();
  for (int i = 0; i < 8; ++i) {
    if (fs::exists(dir / rel)) return (dir / rel).string();
    if (!dir.has_parent_path() || dir.parent_path() == dir) break;
    dir = dir.parent_path();
  }
  // next to the source tree this binary was built from
  const fs::path src = fs::path(__FILE__).parent_path().parent_path().parent_path() / rel;
  return fs::exists(src) ? src.string() : std::string();
}

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Reference times in 50 digits: the ellipse form of PHYSICS.md with the double inputs exactly.
std::vector<double> ReferenceTimes(const Rails& rails, double x0, const std::vector<double>& xs) {
  using std::sqrt;
  using boost::multiprecision::atan2;
  using boost::multiprecision::sin;
  using boost::multiprecision::cos;
  using boost::multiprecision::cosh;
  using boost::multiprecision::sinh;
  using boost::multiprecision::asinh;
  const Big a = kA, b = kB, B = rails.tan_theta, T = rails.tan_half_alpha, g = kG;
  const Big A = a * T / b, P = 1 + A * A + B * B, sp = sqrt(P);
  const Big x_max = sqrt(a * a + (b / T) * (b / T));
  const Big z_eq = a * sqrt(A * A + B * B) / A;
  const Big psi0 = atan2(B, A * sp), gamma = atan2(A * B, sp), q = A * A / P;
  const Big inertia = Big(2) / 5;
  auto u_of = [&](double x) {
    const Big s = Big(x) / x_max;
    return atan2(s, sqrt((1 - s) * (1 + s))) - psi0;
  };
  const Big u0 = u_of(x0);
  auto f = [&](const Big& w) {
    const Big ch = cosh(w / 2), sh = sinh(w / 2);
    const Big a1 = u0 * ch * ch, a2 = u0 * sh * sh, u = a1 + a2, psi = u + psi0;
    const Big M = x_max * x_max * cos(psi) * cos(psi) + z_eq * z_eq * sin(u) * sin(u);
    const Big wg = psi + gamma;
    const Big d = cos(wg) * cos(wg) + q * sin(wg) * sin(wg);
    const Big K = 1 + inertia / d;
    const Big s1 = a1 == 0 ? Big(1) : sin(a1) / a1, s2 = a2 == 0 ? Big(1) : sin(a2) / a2;
    return Big(sqrt(K * M / (g * z_eq * s1 * s2)));
  };
  std::vector<double> out;
  Big t = 0, w_prev = 0;
  for (double x : xs) {
    const Big u = u_of(x);
    const Big w = 2 * asinh(sqrt((u - u0) / (2 * u0)));
    t += boost::math::quadrature::gauss_kronrod<Big, 61>::integrate(f, w_prev, w, 12, Big(1e-35));
    out.push_back(static_cast<double>(t));
    w_prev = w;
  }
  return out;
}

double MaxRelError(const std::vector<double>& got, const std::vector<double>& ref) {
  double worst = 0;
  for (size_t i = 0; i < ref.size(); ++i) worst = std::max(worst, std::abs(got[i] / ref[i] - 1));
  return worst;
}

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Best of 5 repeats of ≥ 0.1 s each; microseconds per call (wall time), and the thread CPU time
// of the same repeats in *cpu_micros (what a loaded, shared machine still measures fairly).
template <class Work>
double TimeIt(const Work& work, double* cpu_micros = nullptr) {
  using Clock = std::chrono::steady_clock;
  double best = 1e300, best_cpu = 1e300;
  for (int r = 0; r < 5; ++r) {
    long n = 0;
    const auto start = Clock::now();
    const double cpu_start = ThreadCpuSeconds();
    double elapsed = 0;
    do {
      work();
      ++n;
      elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    } while (elapsed < 0.1);
    best = std::min(best, elapsed / n);
    best_cpu = std::min(best_cpu, (ThreadCpuSeconds() - cpu_start) / n);
  }
  if (cpu_micros) *cpu_micros = best_cpu * 1e6;
  return best * 1e6;
}

void Run(const Flags& f) {
  const Rails rails = Rails::FromAngles(kThetaDeg * M_PI / 180, kAlphaDeg * M_PI / 180);
  const Scene scene(Body::Spheroid(kA, kB), rails);
  const double x0 = 1.05 * *scene.x_eq();
  const double x_end = 0.99 * scene.x_max();
  std::vector<double> xs;
  for (int i = 1; i <= kPoints; ++i) xs.push_back(x0 + (x_end - x0) * i / kPoints);
  const std::vector<double> ref = ReferenceTimes(rails, x0, xs);
  std::printf("uphill bench motion: spheroid a = 20 mm, b = 32 mm, theta = 1 deg, alpha = 30 deg,\n"
              "released at rest at 1.05 X = %.6f mm; %d positions up to 0.99 x_max = %.6f mm (t = %.6f s).\n"
              "Error: max relative error of the 200 times against cpp_bin_float_50 (GK61, 1e-35).\n"
              "Time: wall time per 200-point trajectory, one core, best of 5.\n\n",
              x0 * 1e3, kPoints, x_end * 1e3, ref.back());
  std::vector<Row> rows;
  std::vector<double> got(kPoints);
  for (int e = 3; e <= 13 && !f.release_only; e += 2) {
    const double tol = std::pow(10.0, -e);
    for (MotionMethod m : {MotionMethod::kQuadrature, MotionMethod::kOde}) {
      MotionOptions o;
      o.method = m;
      o.tolerance = tol;
      auto work = [&] {
        const Motion motion(scene, x0, o);
        for (int i = 0; i < kPoints; ++i) got[i] = motion.TimeAt(xs[i]);
      };
      work();
      const double err = MaxRelError(got, ref);
      rows.push_back({m == MotionMethod::kOde ? "uphill ode (Dopri5, TimeAt)" : "uphill quadrature (GK31 adaptive, TimeAt)",
                      "tol 1e-" + std::to_string(e), TimeIt(work), err});
    }
  }
  // The fast path: node count from the a-priori estimate (per tolerance), and fixed counts.
  std::vector<ReleaseKernel> kernels = {ReleaseKernel::kScalar};
  if (ReleaseKernelAvailable(ReleaseKernel::kAvx2)) kernels.insert(kernels.begin(), ReleaseKernel::kAvx2);
  for (ReleaseKernel kernel : kernels) {
    const std::string name = "uphill ReleaseTimes, " + ReleaseKernelName(kernel);
    // Fixed node counts are a separate curve (same method, no a-priori choice).
    auto add = [&](const ReleaseTimesOptions& o, const std::string& setting) {
      auto work = [&] { ReleaseTimes(scene, x0, xs, got, o); };
      work();
      double cpu = 0;
      const double wall = TimeIt(work, &cpu);
      rows.push_back({o.nodes ? name + ", fixed nodes" : name, setting, wall, MaxRelError(got, ref), cpu});
    };
    for (int e = 3; e <= 15; e += (e < 11 ? 2 : 1)) {
      ReleaseTimesOptions o;
      o.g = kG;
      o.kernel = kernel;
      o.tolerance = std::pow(10.0, -e);
      add(o, "tol 1e-" + std::to_string(e));
    }
    for (int n : {3, 4, 5, 6}) {
      ReleaseTimesOptions o;
      o.g = kG;
      o.kernel = kernel;
      o.nodes = n;
      add(o, std::to_string(n) + " nodes");
    }
  }

  // Peers.
  std::string why_not;
  const std::string script = f.script.empty() ? FindUpward("tools/bench/motion_peers.py") : f.script;
  if (f.no_python || f.release_only) why_not = f.no_python ? "--no-python" : "--release-only";
  else if (access(f.python.c_str(), X_OK) != 0) why_not = f.python + " not found";
  else if (script.empty()) why_not = "tools/bench/motion_peers.py not found (use --script)";
  else if (std::system((Quote(f.python) + " -c 'import scipy' > /dev/null 2>&1").c_str()) != 0)
    why_not = f.python + " has no SciPy (bash scripts/install-deps.sh --bench)";
  if (why_not.empty()) {
    fs::create_directories(f.out);
    const fs::path problem = fs::path(f.out) / "motion_problem.txt";
    {
      std::ofstream p(problem);
      p.precision(17);
      p << kA << " " << kB << " " << rails.tan_theta << " " << rails.tan_half_alpha << " " << kG << " " << x0 << "\n";
      for (int i = 0; i < kPoints; ++i) p << xs[i] << " " << ref[i] << "\n";
    }
    const std::string cmd = "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 " + Quote(f.python) + " " + Quote(script) + " " +
                            Quote(problem.string());
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string out;
    if (pipe) {
      char buf[4096];
      size_t got_n;
      while ((got_n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, got_n);
      if (pclose(pipe) != 0) why_not = "the peer script failed";
    }
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
      // method|setting|micros|error
      std::vector<std::string> parts;
      std::stringstream ss(line);
      std::string part;
      while (std::getline(ss, part, '|')) parts.push_back(part);
      if (parts.size() == 4) rows.push_back({parts[0], parts[1], std::stod(parts[2]), std::stod(parts[3])});
    }
  }
  std::printf("%-60s %-12s %14s %12s %12s\n", "method", "setting", "time/traj", "max rel err", "(cpu time)");
  for (const Row& r : rows) {
    std::printf("%-60s %-12s %11.1f us %12.2e", r.method.c_str(), r.setting.c_str(), r.micros, r.error);
    if (r.cpu_micros >= 0) std::printf(" %9.1f us", r.cpu_micros);
    std::printf("\n");
  }
  if (!why_not.empty()) std::printf("\nSciPy/NumPy comparison skipped: %s\n", why_not.c_str());
  double best = 1e300, best_cpu = 1e300;
  for (const Row& r : rows)
    if (r.method.rfind("uphill", 0) == 0 && r.error <= 1e-12) {
      best = std::min(best, r.micros);
      if (r.cpu_micros >= 0) best_cpu = std::min(best_cpu, r.cpu_micros);
    }
  std::printf("\nGoal: <= 1e-12 in <= 10 us per trajectory. Fastest uphill row at <= 1e-12: %.1f us wall, "
              "%.1f us thread CPU time (%s).\n",
              best, best_cpu, best <= 10.0 ? "met" : best_cpu <= 10.0 ? "met in CPU time only: the machine is loaded" : "not met");

  // Figure.
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
    plot += std::string(k ? ", " : "") + "'work_precision_motion.dat' index " + std::to_string(k) +
            " with linespoints title '" + methods[k] + "' noenhanced";
  }
  plot += "\n";
  fs::create_directories(f.out);
  report::RenderFigure({"work_precision_motion", "Work-precision of the motion methods",
                        "Time per 200-point trajectory against the largest relative error (spheroid 20x32 mm, "
                        "theta 1 deg, alpha 30 deg, release at 1.05 X).",
                        data, plot},
                       f.out);
  std::printf("figure: %s/work_precision_motion.{svg,png}\n", f.out.c_str());
}

}  // namespace

void AddBenchMotion(CLI::App& bench) {
  auto flags = std::make_shared<Flags>();
  CLI::App* cmd = bench.add_subcommand("motion", "Work-precision of the motion methods, against SciPy/NumPy");
  cmd->add_option("-o,--out", flags->out, "folder for the work-precision figure")->capture_default_str();
  cmd->add_option("--python", flags->python, "Python with SciPy for the comparison")->capture_default_str();
  cmd->add_option("--script", flags->script, "path of tools/bench/motion_peers.py");
  cmd->add_flag("--no-python", flags->no_python, "skip the SciPy/NumPy comparison");
  cmd->add_flag("--release-only", flags->release_only, "only the ReleaseTimes rows (no Motion rows, no peers)");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
