// Simulation: the use case behind `uphill simulate` (docs/simulate.md): the rolling motion of a
// scene's body released at x0 (motion/motion.hpp), sampled at given times, at given positions or
// every dt up to the end of the motion, with its events (falls off, reaches O, turning point,
// comes to rest), and the stable JSON form of the result (SI units; keys in docs/simulate.md).
//
// Errors: InputError named as the command line names the option ("--x0", "--at-times", "--dt",
// "--t-end", "--method", "--mu", ...), with the rule broken, e.g. "--at-times: 2 s is after the
// end of the motion (the motion ends at t = 0.81 s: falls off)".
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "motion/motion.hpp"

namespace uphill {

// How the motion is computed: kAuto picks the ODE where the quadrature cannot (rolling
// resistance μ > 0, or an initial speed for a spheroid on rods), else the quadrature.
enum class SimulationMethod { kAuto, kQuadrature, kOde };

// The ranges Simulate answers for (a ball on a lab's rails); outside them it throws InputError
// naming the flag. Far beyond them the ODE's steps and the end time lose every digit.
inline constexpr double kFastestV0 = 1e3;  // m/s, |v0|
inline constexpr double kLargestG = 1e3;   // m/s²
inline constexpr double kLargestMu = 10;   // slope threshold

struct SimulationRequest {
  double x0 = 0;   // release position of the centre, m
  double v0 = 0;   // initial speed of the centre, m/s, signed (+ away from O), |v0| <= kFastestV0
  double g = 9.80665;  // m/s², in (0, kLargestG]
  double mu = 0;   // rolling resistance (slope threshold), in [0, kLargestMu]
  SimulationMethod method = SimulationMethod::kAuto;
  // Exactly one sampling: times (s, >= 0, within the motion), positions (m, reached by the
  // motion; each adds its passage event), or every dt (s, > 0) up to t_end (s; default: the end
  // of the motion, or where it comes to rest; required when the motion never ends).
  std::vector<double> at_times;
  std::vector<double> at_x;
  std::optional<double> dt;
  std::optional<double> t_end;
};

struct Simulation {
  MotionOptions options;  // as run: the method resolved
  double x0 = 0;
  int direction = 0;      // +1 away from O, −1 toward O, 0 at rest
  std::optional<double> x_eq;  // m (none for the double cone)
  double x_max = 0;            // m
  std::vector<MotionSample> samples;
  std::vector<MotionEvent> events;
};

// Runs the request on `scene`. At most 10^6 samples.
Simulation Simulate(const Scene& scene, const SimulationRequest& request);

// {"x0", "v0", "g", "mu", "method", "direction", "x_eq" (when the body has one), "x_max",
//  "samples": [{"t", "x", "z", "v", "vx", "vz", "angle"}...], "events": [{"kind", "x", "t"}...]},
// SI units; an event's t is null when it is never reached.
nlohmann::json ToJson(const Simulation& simulation);

// `uphill simulate --csv`: the header t_s,x_m,z_m,v_m/s,vx_m/s,vz_m/s,angle_rad, then one line per
// sample with 17 significant digits (SI units).
std::string SimulationCsv(const Simulation& simulation);

// `uphill simulate`'s table: the release, X and x_max, the method, the samples (lengths in
// `length_unit`, an io/units.hpp length unit; speeds in m/s, angles in rad) and the events.
std::string SimulationTable(const Simulation& simulation, const std::string& length_unit);

}  // namespace uphill
