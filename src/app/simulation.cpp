#include "app/simulation.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

// 10 significant digits: what a message needs to name a time or a position.
std::string Short(double v) { return Printf("%.10g", v); }

MotionMethod ChooseMethod(const Scene& scene, const SimulationRequest& r) {
  switch (r.method) {
    case SimulationMethod::kQuadrature:
      if (r.mu > 0.0) throw InputError("--method", "quadrature needs --mu 0 (energy conservation); use ode");
      return MotionMethod::kQuadrature;
    case SimulationMethod::kOde:
      return MotionMethod::kOde;
    case SimulationMethod::kAuto:
      break;
  }
  // ode when the quadrature cannot: rolling resistance, or an initial speed on a spheroid on
  // rods (whose quadrature handles a release from rest only).
  const bool rods_spheroid = scene.body().kind == BodyKind::kSpheroid && scene.rod_radius() > 0.0;
  return r.mu > 0.0 || (rods_spheroid && r.v0 != 0.0) ? MotionMethod::kOde : MotionMethod::kQuadrature;
}

// The motion, with the model's messages named as the command line names the options.
Motion MakeMotion(const Scene& scene, double x0, const MotionOptions& o) {
  try {
    return Motion(scene, x0, o);
  } catch (const InputError& e) {
    const std::string q = e.quantity();
    const std::string flag = q == "x0" || q == "v0" || q == "g" || q == "mu" || q == "method" ? "--" + q : q;
    throw InputError(flag, e.rule());
  }
}

}  // namespace

Simulation Simulate(const Scene& scene, const SimulationRequest& request) {
  // The ranges the motion answers for: a ball on a lab's rails. Far outside them the integrator's
  // steps and the quadrature's end time lose every digit (--v0 1e20 m/s gave a NaN end time).
  if (!(request.g > 0.0 && request.g <= kLargestG))
    throw InputError("--g", "must be > 0 and at most " + Short(kLargestG) + " m/s2 (got " + Short(request.g) + " m/s2)");
  if (!(request.mu >= 0.0 && request.mu <= kLargestMu))
    throw InputError("--mu", "must be between 0 and " + Short(kLargestMu) + " (got " + Short(request.mu) + ")");
  if (!(std::abs(request.v0) <= kFastestV0))
    throw InputError("--v0", "must be at most " + Short(kFastestV0) + " m/s in size (got " + Short(request.v0) + " m/s)");
  Simulation s;
  s.options.v0 = request.v0;
  s.options.g = request.g;
  s.options.mu = request.mu;
  s.options.method = ChooseMethod(scene, request);
  const Motion motion = MakeMotion(scene, request.x0, s.options);
  s.x0 = motion.x0();
  s.direction = motion.direction();
  s.x_eq = scene.x_eq();
  s.x_max = scene.x_max();

  const int modes = !request.at_times.empty() + !request.at_x.empty() + request.dt.has_value();
  if (modes != 1) throw InputError("--at-times/--at-x/--dt", "give exactly one of them");
  s.events = motion.events();
  const double end = motion.end_time();
  const std::string end_text =
      std::isfinite(end) ? " (the motion ends at t = " + Short(end) + " s: " + EventName(s.events.back().kind) + ")"
                         : "";
  if (!request.at_times.empty()) {
    for (double t : request.at_times) {
      if (t < 0.0) throw InputError("--at-times", "must be >= 0 s (got " + Short(t) + " s)");
      if (t > end) throw InputError("--at-times", Short(t) + " s is after the end of the motion" + end_text);
      s.samples.push_back(motion.At(t));
    }
  } else if (!request.at_x.empty()) {
    for (double x : request.at_x) {
      const double t = motion.TimeAt(x);
      if (!std::isfinite(t))
        throw InputError("--at-x", Short(x * 1e3) + " mm is never reached (released at " + Short(motion.x0() * 1e3) +
                                       " mm, direction " + std::to_string(motion.direction()) + ")" + end_text);
      s.samples.push_back(motion.AtPosition(x));
      s.events.push_back(motion.PositionEvent(x));
    }
  } else {
    const double dt = *request.dt;
    if (!(dt > 0.0)) throw InputError("--dt", "must be > 0 s");
    double t_stop = end;
    if (request.t_end) {
      t_stop = std::min(end, *request.t_end);
      if (!(t_stop >= 0.0)) throw InputError("--t-end", "must be >= 0 s");
    } else if (!std::isfinite(t_stop)) {
      // Comes to rest: stop there. Otherwise (cone toward its apex, at rest at X): --t-end.
      if (!s.events.empty() && s.events.back().kind == MotionEventKind::kRest && s.events.back().t > 0.0)
        t_stop = s.events.back().t;
      else
        throw InputError("--t-end", "is needed: this motion has no end event (" +
                                        std::string(motion.direction() == 0 ? "it stays at rest" : "it never ends") +
                                        ")");
    }
    if (t_stop / dt > 1e6) throw InputError("--dt", "gives more than 10^6 samples; use a larger step");
    const long n = static_cast<long>(std::floor(t_stop / dt));
    for (long i = 0; i <= n; ++i) s.samples.push_back(motion.At(i * dt));
    if (s.samples.back().t < t_stop) s.samples.push_back(motion.At(t_stop));
  }
  return s;
}

nlohmann::json ToJson(const Simulation& s) {
  nlohmann::json j;
  j["x0"] = s.x0;
  j["v0"] = s.options.v0;
  j["g"] = s.options.g;
  j["mu"] = s.options.mu;
  j["method"] = s.options.method == MotionMethod::kOde ? "ode" : "quadrature";
  j["direction"] = s.direction;
  if (s.x_eq) j["x_eq"] = *s.x_eq;
  j["x_max"] = s.x_max;
  nlohmann::json samples = nlohmann::json::array();
  for (const auto& m : s.samples)
    samples.push_back({{"t", m.t}, {"x", m.x}, {"z", m.z}, {"v", m.v}, {"vx", m.vx}, {"vz", m.vz}, {"angle", m.angle}});
  j["samples"] = samples;
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : s.events) {
    nlohmann::json event{{"kind", EventName(e.kind)}, {"x", e.x}};
    event["t"] = std::isfinite(e.t) ? nlohmann::json(e.t) : nlohmann::json(nullptr);
    events.push_back(event);
  }
  j["events"] = events;
  return j;
}

namespace {

std::string Num(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

}  // namespace

std::string SimulationCsv(const Simulation& r) {
  std::ostringstream out;
  out << "t_s,x_m,z_m,v_m/s,vx_m/s,vz_m/s,angle_rad\n";
  out << std::setprecision(17);
  for (const auto& s : r.samples)
    out << s.t << "," << s.x << "," << s.z << "," << s.v << "," << s.vx << "," << s.vz << "," << s.angle << "\n";
  return out.str();
}

std::string SimulationTable(const Simulation& r, const std::string& length_unit) {
  std::ostringstream out;
  const std::string& lu = length_unit;
  const auto L = [&](double v) { return ToUnit(v, Dimension::kLength, lu); };
  out << "released at x0 = " << Num(L(r.x0)) << " " << lu;
  if (r.x_eq) out << "  (X = " << Num(L(*r.x_eq)) << " " << lu << ")";
  out << ", x_max = " << Num(L(r.x_max)) << " " << lu << ", method "
      << (r.options.method == MotionMethod::kOde ? "ode" : "quadrature") << "\n";
  const auto col = [](const std::string& h) { return std::string(" ") + std::string(h.size() < 15 ? 15 - h.size() : 0, ' ') + h; };
  out << col("t [s]") << col("x [" + lu + "]") << col("z [" + lu + "]") << col("v [m/s]") << col("vx [m/s]")
      << col("vz [m/s]") << col("angle [rad]") << "\n";
  out << std::setprecision(9);
  for (const auto& s : r.samples) {
    for (double v : {s.t, L(s.x), L(s.z), s.v, s.vx, s.vz, s.angle}) out << " " << std::setw(15) << v + 0.0;
    out << "\n";
  }
  out << "events:\n";
  if (r.events.empty()) out << "  none (rolls toward the apex; it never gets there)\n";
  for (const auto& e : r.events)
    out << "  " << std::left << std::setw(14) << EventName(e.kind) << std::right << " t = " << std::setprecision(12)
        << e.t << " s   x = " << L(e.x) << " " << lu << "\n";
  return out.str();
}

}  // namespace uphill
