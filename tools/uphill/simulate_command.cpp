// `uphill simulate`: the rolling motion released at --x0 (src/motion): samples at given times,
// at given positions, or every --dt up to the end of the motion, and the events (falls off,
// reaches O, turning point, comes to rest) with their times. Table with units, CSV or JSON (SI).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "scene_flags.hpp"

namespace uphill::cli {
namespace {

struct SimulateFlags {
  SceneFlags scene;
  std::string x0, v0 = "0m/s", g = "9.80665m/s2", mu = "0";
  std::string at_times, at_x, dt, t_end;
  std::string method = "auto";
  bool csv = false, json = false;
  std::string length_unit = "mm";
};

std::vector<double> ParseList(const std::string& text, Dimension dimension, const std::string& flag) {
  std::vector<double> out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    out.push_back(ParseQuantity(item, dimension, flag));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::string Num(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

struct Result {
  std::vector<MotionSample> samples;
  std::vector<MotionEvent> events;
};

Result Simulate(const SimulateFlags& f, const Scene& scene, const Motion& motion) {
  const int modes = !f.at_times.empty() + !f.at_x.empty() + !f.dt.empty();
  if (modes != 1) throw InputError("--at-times/--at-x/--dt", "give exactly one of them");
  Result r;
  r.events = motion.events();
  const double end = motion.end_time();
  const std::string end_text =
      std::isfinite(end) ? " (the motion ends at t = " + Num(end) + " s: " + EventName(r.events.back().kind) + ")" : "";
  if (!f.at_times.empty()) {
    for (double t : ParseList(f.at_times, Dimension::kTime, "--at-times")) {
      if (t < 0.0) throw InputError("--at-times", "must be >= 0 s (got " + Num(t) + " s)");
      if (t > end) throw InputError("--at-times", Num(t) + " s is after the end of the motion" + end_text);
      r.samples.push_back(motion.At(t));
    }
  } else if (!f.at_x.empty()) {
    for (double x : ParseList(f.at_x, Dimension::kLength, "--at-x")) {
      const double t = motion.TimeAt(x);
      if (!std::isfinite(t))
        throw InputError("--at-x", Num(x * 1e3) + " mm is never reached (released at " + Num(motion.x0() * 1e3) +
                                       " mm, direction " + std::to_string(motion.direction()) + ")" + end_text);
      r.samples.push_back(motion.AtPosition(x));
      r.events.push_back(motion.PositionEvent(x));
    }
  } else {
    const double dt = ParseQuantity(f.dt, Dimension::kTime, "--dt");
    if (!(dt > 0.0)) throw InputError("--dt", "must be > 0 s");
    double t_stop = end;
    if (!f.t_end.empty()) {
      t_stop = std::min(end, ParseQuantity(f.t_end, Dimension::kTime, "--t-end"));
      if (!(t_stop >= 0.0)) throw InputError("--t-end", "must be >= 0 s");
    } else if (!std::isfinite(t_stop)) {
      // Comes to rest: stop there. Otherwise (cone toward its apex, at rest at X): --t-end.
      if (!r.events.empty() && r.events.back().kind == MotionEventKind::kRest && r.events.back().t > 0.0)
        t_stop = r.events.back().t;
      else
        throw InputError("--t-end", "is needed: this motion has no end event (" +
                                        std::string(motion.direction() == 0 ? "it stays at rest" : "it never ends") + ")");
    }
    if (t_stop / dt > 1e6) throw InputError("--dt", "gives more than 10^6 samples; use a larger step");
    const long n = static_cast<long>(std::floor(t_stop / dt));
    for (long i = 0; i <= n; ++i) r.samples.push_back(motion.At(i * dt));
    if (r.samples.back().t < t_stop) r.samples.push_back(motion.At(t_stop));
  }
  (void)scene;
  return r;
}

nlohmann::json EventJson(const MotionEvent& e) {
  nlohmann::json j{{"kind", EventName(e.kind)}, {"x", e.x}};
  j["t"] = std::isfinite(e.t) ? nlohmann::json(e.t) : nlohmann::json(nullptr);
  return j;
}

void Print(const SimulateFlags& f, const Scene& scene, const Motion& motion, const MotionOptions& o, const Result& r) {
  if (f.json) {
    nlohmann::json j;
    j["x0"] = motion.x0();
    j["v0"] = o.v0;
    j["g"] = o.g;
    j["mu"] = o.mu;
    j["method"] = o.method == MotionMethod::kOde ? "ode" : "quadrature";
    j["direction"] = motion.direction();
    if (scene.x_eq()) j["x_eq"] = *scene.x_eq();
    j["x_max"] = scene.x_max();
    nlohmann::json samples = nlohmann::json::array();
    for (const auto& s : r.samples)
      samples.push_back({{"t", s.t}, {"x", s.x}, {"z", s.z}, {"v", s.v}, {"vx", s.vx}, {"vz", s.vz}, {"angle", s.angle}});
    j["samples"] = samples;
    nlohmann::json events = nlohmann::json::array();
    for (const auto& e : r.events) events.push_back(EventJson(e));
    j["events"] = events;
    std::cout << j.dump(2) << "\n";
    return;
  }
  if (f.csv) {
    std::cout << "t_s,x_m,z_m,v_m/s,vx_m/s,vz_m/s,angle_rad\n";
    std::cout << std::setprecision(17);
    for (const auto& s : r.samples)
      std::cout << s.t << "," << s.x << "," << s.z << "," << s.v << "," << s.vx << "," << s.vz << "," << s.angle << "\n";
    return;
  }
  const std::string& lu = f.length_unit;
  const auto L = [&](double v) { return ToUnit(v, Dimension::kLength, lu); };
  std::cout << "released at x0 = " << Num(L(motion.x0())) << " " << lu;
  if (scene.x_eq()) std::cout << "  (X = " << Num(L(*scene.x_eq())) << " " << lu << ")";
  std::cout << ", x_max = " << Num(L(scene.x_max())) << " " << lu << ", method "
            << (o.method == MotionMethod::kOde ? "ode" : "quadrature") << "\n";
  const auto col = [](const std::string& h) { return std::string(" ") + std::string(h.size() < 15 ? 15 - h.size() : 0, ' ') + h; };
  std::cout << col("t [s]") << col("x [" + lu + "]") << col("z [" + lu + "]") << col("v [m/s]") << col("vx [m/s]")
            << col("vz [m/s]") << col("angle [rad]") << "\n";
  std::cout << std::setprecision(9);
  for (const auto& s : r.samples) {
    for (double v : {s.t, L(s.x), L(s.z), s.v, s.vx, s.vz, s.angle}) std::cout << " " << std::setw(15) << v + 0.0;
    std::cout << "\n";
  }
  std::cout << "events:\n";
  if (r.events.empty()) std::cout << "  none (rolls toward the apex; it never gets there)\n";
  for (const auto& e : r.events)
    std::cout << "  " << std::left << std::setw(14) << EventName(e.kind) << std::right << " t = " << std::setprecision(12)
              << e.t << " s   x = " << L(e.x) << " " << lu << "\n";
}

void Run(const SimulateFlags& f) {
  if (UnitFactor(Dimension::kLength, f.length_unit) == 0.0)
    throw InputError("--length-unit", "must be one of " + AcceptedUnits(Dimension::kLength));
  if (f.json && f.csv) throw InputError("--csv/--json", "give at most one of them");
  const Scene scene = ParseConfiguration(FlagSource(f.scene)).MakeScene();
  if (f.x0.empty()) throw InputError("--x0", "is required (release position, with unit, e.g. --x0 120mm)");
  const double x0 = ParseQuantity(f.x0, Dimension::kLength, "--x0");
  MotionOptions o;
  o.v0 = ParseQuantity(f.v0, Dimension::kVelocity, "--v0");
  o.g = ParseQuantity(f.g, Dimension::kAcceleration, "--g");
  o.mu = ParseQuantity(f.mu, Dimension::kDimensionless, "--mu");
  if (!(o.g > 0.0)) throw InputError("--g", "must be > 0");
  if (!(o.mu >= 0.0)) throw InputError("--mu", "must be >= 0");
  if (f.method == "quadrature") {
    o.method = MotionMethod::kQuadrature;
    if (o.mu > 0.0) throw InputError("--method", "quadrature needs --mu 0 (energy conservation); use ode");
  } else if (f.method == "ode") {
    o.method = MotionMethod::kOde;
  } else if (f.method == "auto") {
    // ode when the quadrature cannot: rolling resistance, or an initial speed on a spheroid on
    // rods (whose quadrature handles a release from rest only).
    const bool rods_spheroid = scene.body().kind == BodyKind::kSpheroid && scene.rod_radius() > 0.0;
    o.method = o.mu > 0.0 || (rods_spheroid && o.v0 != 0.0) ? MotionMethod::kOde : MotionMethod::kQuadrature;
  } else {
    throw InputError("--method", "must be quadrature, ode or auto (got '" + f.method + "')");
  }
  std::optional<Motion> motion;
  try {
    motion.emplace(scene, x0, o);
  } catch (const InputError& e) {
    const std::string q = e.quantity();
    const std::string flag = q == "x0" || q == "v0" || q == "g" || q == "mu" || q == "method" ? "--" + q : q;
    throw InputError(flag, e.rule());
  }
  const Result r = Simulate(f, scene, *motion);
  Print(f, scene, *motion, o, r);
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto flags = std::make_shared<SimulateFlags>();
  CLI::App* cmd = app.add_subcommand("simulate", "Rolling motion released at --x0: x(t), speeds, events");
  AddSceneFlags(cmd, &flags->scene);
  cmd->add_option("--x0", flags->x0, "release position (centre's x), with unit, e.g. 120mm (required)");
  cmd->add_option("--v0", flags->v0, "initial speed of the centre, signed (+ away from O), e.g. 0.1m/s")
      ->capture_default_str();
  cmd->add_option("--g", flags->g, "gravitational acceleration, e.g. 9.81m/s2")->capture_default_str();
  cmd->add_option("--mu", flags->mu, "rolling resistance (slope threshold, needs the ode method)")
      ->capture_default_str();
  cmd->add_option("--at-times", flags->at_times, "sample times, comma-separated, with unit (s, ms)");
  cmd->add_option("--at-x", flags->at_x, "sample positions, comma-separated, with unit");
  cmd->add_option("--dt", flags->dt, "sample every dt (with unit) up to the end of the motion");
  cmd->add_option("--t-end", flags->t_end, "with --dt: stop at this time (needed when the motion never ends)");
  cmd->add_option("--method", flags->method, "quadrature, ode or auto (ode when --mu > 0, or --v0 != 0 for a spheroid on rods)")->capture_default_str();
  cmd->add_flag("--csv", flags->csv, "CSV output (SI, units in the header)");
  cmd->add_flag("--json", flags->json, "JSON output (SI; keys in README)");
  cmd->add_option("--length-unit", flags->length_unit, "length unit of the table: mm, cm, m, in")
      ->capture_default_str();
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
