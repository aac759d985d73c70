// `uphill bench fit`: time per fit of every method, and how far each lands from an independent
// extended-precision solution, for N = 10², 10⁴, 10⁶ straight-line rows with errors in both
// variables (and the friction model at 10², 10⁴); then the same rows through NumPy/SciPy peers
// (tools/bench/fit_peers.py, run by /usr/bin/python3 as a subprocess, the data passed in a raw float64
// file so both sides fit the very same doubles), and an X ≈ 1e9 case where the peers that do not
// centre lose digits.
//
// References are written here, not taken from the library, so that a shared mistake cannot hide:
//   ols, wls  closed forms (centred sums) in boost::multiprecision::cpp_bin_float_50;
//   york      York et al. (2004)'s iteration and their eq. 13 errors in long double;
//   robust    Huber's objective (σ_i = u(Y_i), δ = 1.345) minimised by Newton steps on its
//             piecewise-quadratic form in long double; errors the IRLS ones at the final weights;
//   friction  Gauss-Newton on Σ (Y − x_rest(μ))²/u(Y)² in long double, x_rest and dx_rest/dμ
//             from the closed form x_max·K/sqrt(PA² + K²) (the model's SpheroidOnLineRails<long
//             double>: the model, not the fit's code path).
// "max rel dev" is the largest |v − v_ref|/|v_ref| over the slope, intercept and both standard
// errors in the method's primary convention (friction: μ and its error). The inputs are the
// doubles as stored; the references treat them as exact.
//
// Times are thread CPU time (CLOCK_THREAD_CPUTIME_ID; time.thread_time() in Python), best of
// --repeats, for the whole call (validation, standardisation, seed, Ceres, refinement,
// covariance, per-row results), i.e. what a caller pays.

#include <algorithm>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_real_distribution.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "commands.hpp"
#include "model/number_text.hpp"
#include "fit/friction_fit.hpp"
#include "fit/least_squares_line.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"
#include "model/spheroid_on_line_rails.hpp"

namespace uphill::cli {
namespace {

namespace fs = std::filesystem;
using Big = boost::multiprecision::cpp_bin_float_50;

struct FitBenchFlags {
  std::vector<std::uint64_t> sizes = {100, 10'000, 1'000'000};
  std::vector<std::uint64_t> friction_sizes = {100, 10'000};
  std::uint64_t offset_rows = 10'000;
  std::uint64_t seed = 1;
  int repeats = 3;
  std::string python = "/usr/bin/python3";
  std::string script;  // default: tools/bench/fit_peers.py found upward
  bool no_peers = false;
  bool no_odr = false;
};

// Y = c + k·t + u(Y)·n₁, X = t + u(X)·n₂: true t uniform on [t0, t0 + spread], u(X) and u(Y)
// varying per row (so that the weighted fits differ from OLS), Gaussian errors.
LineData StraightLine(std::size_t n, std::uint64_t seed, double t0, double spread, double ux_scale) {
  boost::random::mt19937_64 engine(seed);
  boost::random::uniform_real_distribution<double> unit(0.0, 1.0);
  boost::random::normal_distribution<double> normal;
  const double k = 2.0, c = 1.0;
  LineData d;
  d.x.resize(n);
  d.y.resize(n);
  d.u_x.resize(n);
  d.u_y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0 + spread * unit(engine);
    d.u_x[i] = ux_scale * (0.05 + 0.15 * unit(engine));
    d.u_y[i] = ux_scale * (0.1 + 0.3 * unit(engine));
    d.x[i] = t + d.u_x[i] * normal(engine);
    d.y[i] = c + k * (t - t0) + d.u_y[i] * normal(engine);
  }
  return d;
}

// The lab spheroid on settings around the sample experiments (L 1.10-1.25 m, D 0.10-0.20 m,
// H = 0.3 m), Y = x_rest(μ = 0.05) + N(0, (0.5 mm)²).
constexpr double kSpheroidA = 0.015875, kSpheroidB = 0.0254, kMu = 0.05, kUy = 5e-4;
FrictionData FrictionRows(std::size_t n, std::uint64_t seed) {
  boost::random::mt19937_64 engine(seed);
  boost::random::uniform_real_distribution<double> uL(1.10, 1.25), uD(0.10, 0.20);
  boost::random::normal_distribution<double> normal;
  FrictionData d;
  for (std::size_t i = 0; i < n; ++i) {
    const double L = uL(engine), D = uD(engine);
    d.scenes.emplace_back(Body::Spheroid(kSpheroidA, kSpheroidB),
                          Rails::FromApparatus(L, 0.3, D, LConvention::kHorizontal), 0.0);
    d.y.push_back(d.scenes.back().Rest(kMu)->high + kUy * normal(engine));
    d.u_y.push_back(kUy);
  }
  return d;
}

// --- references ------------------------------------------------------------------------------

struct Reference {
  std::vector<double> values;  // k, c, se_k, se_c (friction: μ, se_μ)
};

// OLS (weighted = false: scaled errors s·sqrt((XᵀX)⁻¹)) or WLS (w = 1/u(Y)², unscaled errors),
// centred sums in 50 digits.
Reference LeastSquaresReference(const LineData& d, bool weighted) {
  const std::size_t n = d.size();
  Big sw = 0, swx = 0, swy = 0;
  std::vector<Big> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    w[i] = weighted ? Big(1) / (Big(d.u_y[i]) * d.u_y[i]) : Big(1);
    sw += w[i];
    swx += w[i] * d.x[i];
    swy += w[i] * d.y[i];
  }
  const Big xm = swx / sw, ym = swy / sw;
  Big sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Big dx = d.x[i] - xm;
    sxx += w[i] * dx * dx;
    sxy += w[i] * dx * (d.y[i] - ym);
  }
  const Big k = sxy / sxx, c = ym - k * xm;
  Big scale = 1;
  if (!weighted) {
    Big ssr = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Big r = d.y[i] - c - k * d.x[i];
      ssr += r * r;
    }
    scale = ssr / (n - 2);
  }
  const Big var_k = scale / sxx, var_c = scale * (1 / sw + xm * xm / sxx);
  return {{static_cast<double>(k), static_cast<double>(c), static_cast<double>(sqrt(var_k)),
           static_cast<double>(sqrt(var_c))}};
}

// York et al. (2004), section III with r_i = 0, in long double, on X centred at a double near
// their mean (the subtraction is exact when both are within a factor 2, and otherwise rounded to
// long double's 64 bits).
Reference YorkReference(const LineData& d) {
  using L = long double;
  const std::size_t n = d.size();
  const double xc = d.x[n / 2];
  std::vector<L> x(n), ux2(n), uy2(n), W(n), beta(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<L>(d.x[i]) - xc;
    ux2[i] = static_cast<L>(d.u_x[i]) * d.u_x[i];
    uy2[i] = static_cast<L>(d.u_y[i]) * d.u_y[i];
  }
  L k = 0, xbar = 0, ybar = 0;
  {  // start: OLS slope
    L sx = 0, sy = 0;
    for (std::size_t i = 0; i < n; ++i) sx += x[i], sy += d.y[i];
    const L mx = sx / n, my = sy / n;
    L sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (d.y[i] - my);
    k = sxy / sxx;
  }
  const auto means = [&] {
    L sw = 0, swx = 0, swy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      W[i] = 1 / (uy2[i] + k * k * ux2[i]);
      sw += W[i];
      swx += W[i] * x[i];
      swy += W[i] * d.y[i];
    }
    xbar = swx / sw;
    ybar = swy / sw;
    return sw;
  };
  L previous_step = INFINITY;
  for (int it = 0; it < 500; ++it) {
    means();
    L num = 0, den = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L U = x[i] - xbar, V = d.y[i] - ybar;
      beta[i] = W[i] * (U * uy2[i] + k * V * ux2[i]);
      num += W[i] * beta[i] * V;
      den += W[i] * beta[i] * U;
    }
    const L next = num / den, step = std::fabs(next - k);
    k = next;
    // Linear convergence down to the rounding floor of long double, where the step stops
    // shrinking.
    if (step == 0 || (step <= 1e-17L * std::fabs(k) && step >= previous_step)) break;
    previous_step = step;
  }
  const L sw = means();
  const L c = ybar - k * xbar;  // intercept in centred X
  // Errors (York 2004 eq. 13): adjusted x_i = xbar + β_i, their weighted mean and spread.
  L swxi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L U = x[i] - xbar, V = d.y[i] - ybar;
    beta[i] = W[i] * (U * uy2[i] + k * V * ux2[i]);
    swxi += W[i] * (xbar + beta[i]);
  }
  const L xi_bar = swxi / sw;
  L swu2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L u = xbar + beta[i] - xi_bar;
    swu2 += W[i] * u * u;
  }
  const L var_k = 1 / swu2, xi_bar_abs = xi_bar + xc;
  const L var_c = 1 / sw + xi_bar_abs * xi_bar_abs * var_k;
  return {{static_cast<double>(k), static_cast<double>(c - k * xc),
           static_cast<double>(std::sqrt(var_k)), static_cast<double>(std::sqrt(var_c))}};
}

// Huber (δ = 1.345, s_i = r_i/u(Y_i)): minimise Σ ρ(s_i²), ρ(q) = q (|s| ≤ δ), 2δ|s| − δ²
// otherwise, by Newton steps on the current inlier set (exact for a fixed set), halving a step
// that raises the objective. Errors: (Σ w_i x_i x_iᵀ/u_i²)⁻¹, w_i = min(1, δ/|s_i|).
Reference RobustReference(const LineData& d, const Reference& wls) {
  using L = long double;
  const std::size_t n = d.size();
  const L delta = 1.345L;
  const double xc = d.x[n / 2];
  std::vector<L> x(n), iu(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<L>(d.x[i]) - xc;
    iu[i] = 1 / static_cast<L>(d.u_y[i]);
  }
  L k = wls.values[0], c = wls.values[1] + static_cast<L>(wls.values[0]) * xc;
  const auto objective = [&](L kk, L cc) {
    L f = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L s = std::fabs((d.y[i] - cc - kk * x[i]) * iu[i]);
      f += s <= delta ? s * s : 2 * delta * s - delta * delta;
    }
    return f;
  };
  L f = objective(k, c);
  L h00 = 0, h01 = 0, h11 = 0;
  for (int it = 0; it < 200; ++it) {
    L g0 = 0, g1 = 0;
    h00 = h01 = h11 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L s = (d.y[i] - c - k * x[i]) * iu[i];
      const L w = std::fabs(s) <= delta ? 1 : delta / std::fabs(s);  // IRLS weight
      const L psi = w * s * iu[i];                                      // ½ dρ/dr
      g0 += psi * x[i];
      g1 += psi;
      if (std::fabs(s) <= delta) {  // Newton: only inliers curve the objective
        h00 += iu[i] * iu[i] * x[i] * x[i];
        h01 += iu[i] * iu[i] * x[i];
        h11 += iu[i] * iu[i];
      }
    }
    const L det = h00 * h11 - h01 * h01;
    L dk = (h11 * g0 - h01 * g1) / det, dc = (h00 * g1 - h01 * g0) / det;
    bool moved = false;
    for (int half = 0; half < 60; ++half) {
      const L fn = objective(k + dk, c + dc);
      if (fn <= f) {
        moved = fn < f || dk != 0 || dc != 0;
        k += dk;
        c += dc;
        f = fn;
        break;
      }
      dk /= 2;
      dc /= 2;
    }
    if (!moved || (std::fabs(dk) <= 1e-18L * std::fabs(k) && std::fabs(dc) <= 1e-18L * (std::fabs(c) + 1)))
      break;
  }
  // IRLS covariance at the final weights.
  h00 = h01 = h11 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L s = (d.y[i] - c - k * x[i]) * iu[i];
    const L w = (std::fabs(s) <= delta ? 1 : delta / std::fabs(s)) * iu[i] * iu[i];
    h00 += w * x[i] * x[i];
    h01 += w * x[i];
    h11 += w;
  }
  const L det = h00 * h11 - h01 * h01;
  const L var_k = h11 / det, var_cc = h00 / det, cov = -h01 / det;
  const L var_c = var_cc - 2 * xc * cov + static_cast<L>(xc) * xc * var_k;  // c = c_centred − k·xc
  return {{static_cast<double>(k), static_cast<double>(c - k * xc),
           static_cast<double>(std::sqrt(var_k)), static_cast<double>(std::sqrt(var_c))}};
}

// Gauss-Newton in long double on Σ (Y − x_rest(μ))²/u², with
// dx_rest/dμ = x_max·PA²(1 + A²)/(PA² + K²)^(3/2), K = tanθ + μ(1 + A²).
Reference FrictionReference(const FrictionData& d) {
  using L = long double;
  L mu = kMu, h = 0;
  for (int it = 0; it < 100; ++it) {
    L g = 0;
    h = 0;
    for (std::size_t i = 0; i < d.size(); ++i) {
      const Rails& rails = d.scenes[i].rails();
      const SpheroidOnLineRails<L> path(kSpheroidA, kSpheroidB, rails.tan_theta,
                                        rails.tan_half_alpha);
      const L A2 = path.A() * path.A(), PA2 = path.P() * A2, K = rails.tan_theta + mu * (1 + A2);
      const L j = path.x_max() * PA2 * (1 + A2) / std::pow(PA2 + K * K, 1.5L);
      const L w = 1 / (static_cast<L>(d.u_y[i]) * d.u_y[i]);
      g += w * j * (d.y[i] - path.RestX(mu));
      h += w * j * j;
    }
    const L step = g / h;
    mu += step;
    if (std::fabs(step) <= 1e-18L * mu) break;
  }
  return {{static_cast<double>(mu), static_cast<double>(1 / std::sqrt(h))}};
}

double MaxRelDev(const std::vector<double>& values, const Reference& ref) {
  double worst = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i)
    worst = std::max(worst, std::abs(values[i] - ref.values[i]) / std::abs(ref.values[i]));
  return worst;
}

std::vector<double> LineValues(const FitReport& fit) {
  const ErrorScaling scaling = fit.primary_scaling;
  return {fit.slope(), fit.intercept(), fit.StandardError("k", scaling).value_or(NAN),
          fit.StandardError("c", scaling).value_or(NAN)};
}

// --- table ---------------------------------------------------------------------------------------


std::string Time(double s) {
  if (s < 1e-3) return Printf("%.1f us", s * 1e6);
  if (s < 1.0) return Printf("%.2f ms", s * 1e3);
  return Printf("%.3f s", s);
}

struct PeerResult {
  std::string name;
  double seconds = 0.0, dev = 0.0;
};

struct Measured {
  std::string method;
  std::size_t n = 0;
  double seconds = 0.0, dev = 0.0;
  std::vector<PeerResult> peers;
};

void PrintHeader() {
  std::printf("%-8s %9s %10s %11s | %-16s %10s %9s %11s\n", "method", "N", "time", "max rel dev",
              "peer", "peer time", "ratio", "peer dev");
}

void Print(const Measured& m) {
  std::printf("%-8s %9.0e %10s %11.2g |", m.method.c_str(), static_cast<double>(m.n),
              Time(m.seconds).c_str(), m.dev);
  if (m.peers.empty()) std::printf("\n");
  for (std::size_t p = 0; p < m.peers.size(); ++p) {
    const PeerResult& peer = m.peers[p];
    if (p > 0) std::printf("%-8s %9s %10s %11s |", "", "", "", "");
    std::printf(" %-16s %10s %8.1fx %11.2g\n", peer.name.c_str(), Time(peer.seconds).c_str(),
                peer.seconds / m.seconds, peer.dev);
  }
}

// The peers' fits of `d` (empty when they cannot run).
std::optional<nlohmann::json> RunPeers(const FitBenchFlags& f, const std::string& script,
                                       const LineData& d) {
  if (script.empty()) return std::nullopt;
  const bench::TemporaryDirectory temporary;
  const fs::path& dir = temporary.path();
  bench::WriteFloat64(dir / "in.f64", {&d.x, &d.y, &d.u_x, &d.u_y});
  const std::string command = bench::OneCorePython(f.python) + " " + bench::ShellQuote(script) + " " +
                              bench::ShellQuote((dir / "in.f64").string()) + " --repeats " +
                              std::to_string(f.repeats) + (f.no_odr ? " --no-odr" : "");
  std::string out;
  if (!bench::Capture(command, &out)) throw std::runtime_error("the peer script failed: " + script);
  return nlohmann::json::parse(out);
}

PeerResult Peer(const nlohmann::json& peers, const std::string& key, const std::string& name,
                const Reference& ref) {
  const nlohmann::json& p = peers.at("fits").at(key);
  PeerResult r;
  r.name = name;
  r.seconds = p.at("seconds");
  r.dev = MaxRelDev({p.at("slope").get<double>(), p.at("intercept").get<double>()},
                    Reference{{ref.values[0], ref.values[1]}});
  return r;
}

// Fits `d` by every line method, against the references and (when given) the peers.
std::vector<Measured> MeasureLines(const FitBenchFlags& f, const LineData& d,
                                   const std::optional<nlohmann::json>& peers, bool robust) {
  const std::size_t n = d.size();
  const Reference ols_ref = LeastSquaresReference(d, false);
  const Reference wls_ref = LeastSquaresReference(d, true);
  const Reference york_ref = YorkReference(d);
  std::vector<Measured> out;
  const auto measure = [&](const std::string& name, auto fit, const Reference& ref) {
    FitReport report;
    Measured m{name, n, bench::BestOf(f.repeats, [&] { report = fit(); }), 0.0, {}};
    m.dev = MaxRelDev(LineValues(report), ref);
    return m;
  };
  out.push_back(measure("ols", [&] { return FitOrdinaryLeastSquares(d); }, ols_ref));
  out.push_back(measure("wls", [&] { return FitWeightedLeastSquares(d); }, wls_ref));
  out.push_back(measure("york", [&] { return FitErrorsInVariables(d); }, york_ref));
  if (robust)
    out.push_back(measure("robust", [&] { return FitRobust(d); }, RobustReference(d, wls_ref)));
  if (peers) {
    out[0].peers.push_back(Peer(*peers, "lstsq", "numpy lstsq", ols_ref));
    out[0].peers.push_back(Peer(*peers, "polyfit", "numpy polyfit", ols_ref));
    out[1].peers.push_back(Peer(*peers, "wls_lstsq", "numpy lstsq (w)", wls_ref));
    out[2].peers.push_back(Peer(*peers, "york", "numpy York", york_ref));
    if (peers->at("fits").contains("odr"))
      out[2].peers.push_back(Peer(*peers, "odr", "scipy.odr", york_ref));
  }
  return out;
}

void Run(const FitBenchFlags& f) {
  if (f.repeats < 1) throw InputError("--repeats", "must be at least 1");
  for (std::uint64_t n : f.sizes)
    if (n < 3) throw InputError("--sizes", "every size must be at least 3");
  std::string script = f.script.empty() ? bench::FindUpward("tools/bench/fit_peers.py") : f.script;
  std::string why_not;
  if (f.no_peers) why_not = "--no-peers";
  else if (access(f.python.c_str(), X_OK) != 0) why_not = f.python + " not found";
  else if (script.empty()) why_not = "tools/bench/fit_peers.py not found (use --peer-script)";
  else if (std::system((bench::ShellQuote(f.python) + " -c 'import numpy' > /dev/null 2>&1").c_str()) != 0)
    why_not = f.python + " has no NumPy (bash scripts/install-deps.sh --bench)";
  if (!why_not.empty()) script.clear();

  std::printf(
      "uphill bench fit: one core, thread CPU time per fit (whole call), best of %d.\n"
      "Data: Y = 1 + 2t + u(Y)n, X = t + u(X)n, t ~ U(0, 10), u(X) ~ U(0.05, 0.2), "
      "u(Y) ~ U(0.1, 0.4), seed %llu.\n"
      "max rel dev: largest relative deviation of (k, c, se_k, se_c) [friction: mu, se_mu] from "
      "the extended-precision\nreference (50-digit OLS/WLS, long-double York iteration, Huber "
      "Newton, friction Gauss-Newton); peers: (k, c) only.\n"
      "ratio = peer time / uphill time.%s\n\n",
      f.repeats, static_cast<unsigned long long>(f.seed),
      why_not.empty() ? "" : ("\nPeers skipped: " + why_not).c_str());
  PrintHeader();
  std::map<std::size_t, Measured> york_at;
  for (std::uint64_t n64 : f.sizes) {
    const std::size_t n = static_cast<std::size_t>(n64);
    const LineData d = StraightLine(n, f.seed + n, 0.0, 10.0, 1.0);
    const auto peers = RunPeers(f, script, d);
    for (const Measured& m : MeasureLines(f, d, peers, true)) {
      Print(m);
      if (m.method == "york") york_at[n] = m;
    }
    std::fflush(stdout);
  }
  for (std::uint64_t n64 : f.friction_sizes) {
    const FrictionData d = FrictionRows(static_cast<std::size_t>(n64), f.seed + n64);
    FitReport report;
    Measured m{"friction", d.size(), bench::BestOf(f.repeats, [&] { report = FitFriction(d); }), 0.0, {}};
    m.dev = MaxRelDev({report.Parameter("mu").value, report.Parameter("mu").se_unscaled},
                      FrictionReference(d));
    Print(m);
    std::fflush(stdout);
  }

  // X ≈ 1e9 with a spread of 1 (u scaled down 10×): lstsq/polyfit of the raw design lose digits
  // to the cancellation in XᵀX; the centring fits must not.
  if (f.offset_rows >= 3) {
    const LineData d = StraightLine(static_cast<std::size_t>(f.offset_rows), f.seed, 1e9, 1.0, 0.1);
    std::printf("\nX = 1e9 + t, t ~ U(0, 1), u 10x smaller, N = %llu:\n",
                static_cast<unsigned long long>(f.offset_rows));
    PrintHeader();
    for (const Measured& m : MeasureLines(f, d, RunPeers(f, script, d), false)) Print(m);
  }

  const std::size_t big = f.sizes.empty() ? 0 : static_cast<std::size_t>(f.sizes.back());
  if (york_at.count(big) && !york_at[big].peers.empty()) {
    const Measured& m = york_at[big];
    std::printf("\nGoal at N = %.0e (errors in both variables):", static_cast<double>(big));
    bool all = m.dev <= 1e-12;
    for (const PeerResult& p : m.peers) {
      const double goal = p.name == "scipy.odr" ? 10.0 : 3.0;
      const double ratio = p.seconds / m.seconds;
      all = all && ratio >= goal;
      std::printf(" %.1fx %s (goal >= %.0fx);", ratio, p.name.c_str(), goal);
    }
    std::printf(" max rel dev %.2g (goal <= 1e-12): %s\n", m.dev, all ? "met" : "NOT met");
  }
}

}  // namespace

void AddBenchFit(CLI::App& bench) {
  auto flags = std::make_shared<FitBenchFlags>();
  CLI::App* cmd = bench.add_subcommand(
      "fit", "Line and friction fits: time and accuracy against extended precision and NumPy/SciPy");
  cmd->add_option("--sizes", flags->sizes, "rows of the straight-line cases")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--friction-sizes", flags->friction_sizes, "rows of the friction-model cases")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--offset-rows", flags->offset_rows, "rows of the X = 1e9 case (0: skip)")
      ->capture_default_str();
  cmd->add_option("--seed", flags->seed, "seed of the synthetic data")->capture_default_str();
  cmd->add_option("--repeats", flags->repeats, "timed repeats per fit (the best counts)")
      ->capture_default_str();
  cmd->add_option("--python", flags->python, "Python with NumPy/SciPy for the peers")
      ->capture_default_str();
  cmd->add_option("--peer-script", flags->script, "path of tools/bench/fit_peers.py");
  cmd->add_flag("--no-peers", flags->no_peers, "skip the NumPy/SciPy peers");
  cmd->add_flag("--no-odr", flags->no_odr, "skip scipy.odr (slow at 10^6 rows)");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
