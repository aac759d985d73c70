// `uphill simulate`: the rolling motion released at --x0 (src/motion): samples at given times,
// at given positions, or every --dt up to the end of the motion, and the events (falls off,
// reaches O, turning point, comes to rest) with their times. Table with units, CSV or JSON (SI).
// The sampling and its JSON: src/app/simulation.hpp.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "app/simulation.hpp"
#include "commands.hpp"
#include "flag_checks.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
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
  const CLI::App* command = nullptr;  // to ask which flags were given
};

void Print(const SimulateFlags& f, const Simulation& r) {
  if (f.json) std::cout << ToJson(r).dump(2) << "\n";
  else if (f.csv) std::cout << SimulationCsv(r);
  else std::cout << SimulationTable(r, f.length_unit);
}

void Run(const SimulateFlags& f) {
  if (UnitFactor(Dimension::kLength, f.length_unit) == 0.0)
    throw InputError("--length-unit", "must be one of " + AcceptedUnits(Dimension::kLength));
  if (f.json && f.csv) throw InputError("--csv/--json", "give at most one of them");
  const CLI::App* c = f.command;
  RefuseIgnored(c, "--length-unit", f.json || f.csv, "applies to the table only (CSV and JSON are in SI units)");
  RefuseEmpty(c, "--x0", f.x0, "the release position with unit, e.g. 120mm");
  RefuseEmpty(c, "--at-times", f.at_times, "sample times with unit, e.g. 0.1s,150ms");
  RefuseEmpty(c, "--at-x", f.at_x, "sample positions with unit, e.g. 10mm,20mm");
  RefuseEmpty(c, "--dt", f.dt, "a time step with unit, e.g. 10ms");
  RefuseIgnored(c, "--t-end", !Given(c, "--dt"), "applies only with --dt (the samples of --at-times or --at-x are all given)");
  RefuseEmpty(c, "--t-end", f.t_end, "a time with unit, e.g. 2s");
  const Scene scene = ParseConfiguration(FlagSource(f.scene)).MakeScene();
  if (f.x0.empty()) throw InputError("--x0", "is required (release position, with unit, e.g. --x0 120mm)");
  SimulationRequest request;
  request.x0 = ParseQuantity(f.x0, Dimension::kLength, "--x0");
  request.v0 = ParseQuantity(f.v0, Dimension::kVelocity, "--v0");
  request.g = ParseQuantity(f.g, Dimension::kAcceleration, "--g");
  request.mu = ParseQuantity(f.mu, Dimension::kDimensionless, "--mu");
  if (f.method == "quadrature") {
    request.method = SimulationMethod::kQuadrature;
  } else if (f.method == "ode") {
    request.method = SimulationMethod::kOde;
  } else if (f.method == "auto") {
    request.method = SimulationMethod::kAuto;
  } else {
    throw InputError("--method", "must be quadrature, ode or auto (got '" + f.method + "')");
  }
  if (!f.at_times.empty()) request.at_times = ParseQuantityList(f.at_times, Dimension::kTime, "--at-times");
  if (!f.at_x.empty()) request.at_x = ParseQuantityList(f.at_x, Dimension::kLength, "--at-x");
  if (!f.dt.empty()) request.dt = ParseQuantity(f.dt, Dimension::kTime, "--dt");
  if (!f.t_end.empty()) request.t_end = ParseQuantity(f.t_end, Dimension::kTime, "--t-end");
  Print(f, Simulate(scene, request));
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
  cmd->add_flag("--json", flags->json, "JSON output (SI; keys in docs/simulate.md)");
  cmd->add_option("--length-unit", flags->length_unit, "length unit of the table: mm, cm, m, in")
      ->capture_default_str();
  flags->command = cmd;
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
