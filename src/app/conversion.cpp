#include "app/conversion.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/length_range.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

std::string Length(double metres, const std::string& unit) {
  return Printf("%.6g", ToUnit(metres, Dimension::kLength, unit)) + " " + unit;
}

std::string Degrees(double radians) { return Printf("%.4f", radians * 180.0 / std::numbers::pi) + " deg"; }

std::vector<std::string> Verdict(const ConversionResult& r, const ConversionOptions& options) {
  const std::string& unit = options.length_unit;
  const Scene& s = r.scene;
  std::vector<std::string> out;
  if (const auto* cone = s.cone()) {
    const double theta = s.rails().theta, theta0 = *s.theta0();
    if (cone->rolls_up()) {
      out.push_back("theta = " + Degrees(theta) + " < theta0 = " + Degrees(theta0) +
                    ": the double cone rolls up (away from O, its centre descending) everywhere "
                    "on the rails, from x_low = " + Length(cone->x_low(), unit) +
                    " until the contact reaches its apex at x_fall = " + Length(cone->x_fall(), unit) +
                    ", where it drops.");
    } else {
      out.push_back("theta = " + Degrees(theta) + " >= theta0 = " + Degrees(theta0) +
                    ": the double cone rolls down everywhere (toward O); it never rolls up.");
    }
    if (options.mu) {
      const double slope = std::abs(cone->B());
      out.push_back(s.RestsEverywhere(*options.mu)
                        ? "With mu = " + Printf("%g", *options.mu) + " (>= |dz/dx| = " + Printf("%.4g", slope) +
                              ") it stays at rest wherever it is placed."
                        : "With mu = " + Printf("%g", *options.mu) + " (< |dz/dx| = " + Printf("%.4g", slope) +
                              ") it cannot rest anywhere on the rails.");
    }
    return out;
  }
  const double x_eq = *s.x_eq();
  if (x_eq == 0.0) {
    out.push_back("theta = 0: X = 0, released anywhere on the rails it rolls away from O, its "
                  "centre descending, until it falls through between the rails at x_max = " +
                  Length(s.x_max(), unit) + ".");
  } else {
    out.push_back("X = " + Length(x_eq, unit) +
                  " (unstable equilibrium): released at rest beyond X it rolls up, away from O, "
                  "while its centre descends; released nearer to O it rolls back toward O.");
    out.push_back("It falls through between the rails at x_max = " + Length(s.x_max(), unit) +
                  ", " + Length(*s.FallOffMargin(), unit) + " beyond X.");
  }
  if (const auto crossbar = r.configuration.CrossbarDistance(); crossbar && x_eq > *crossbar) {
    out.push_back("X lies beyond the crossbar (L = " + Length(*crossbar, unit) +
                  " from O, horizontally): this apparatus cannot show the effect.");
  }
  if (r.rest) {
    const std::string from = r.rest->low <= 0.0 ? "O (the band reaches the rails' meeting point)"
                                                : Length(r.rest->low, unit);
    out.push_back("With mu = " + Printf("%g", *options.mu) + " it stays at rest from " + from + " to " +
                  Length(r.rest->high, unit) + " (Y, the farthest rest position).");
  }
  if (r.propagation && r.propagation->rejected.total() > 0) {
    const RejectedTrials& k = r.propagation->rejected;
    std::string reasons;
    const auto reason = [&](std::uint64_t n, const char* what) {
      if (n > 0) reasons += (reasons.empty() ? "" : ", ") + std::to_string(n) + " " + what;
    };
    reason(k.non_positive_length, "a length <= 0");
    reason(k.negative_height, "a height H < 0");
    reason(k.angle_out_of_range, "an angle out of range");
    reason(k.impossible_apparatus, "an impossible along-rail L");
    reason(k.cone_cannot_rest, "a double cone that cannot rest");
    out.push_back("Monte Carlo: " + std::to_string(k.total()) + " of " + std::to_string(r.propagation->trials) +
                  " trials (" + Printf("%.3g", 100.0 * static_cast<double>(k.total()) / static_cast<double>(r.propagation->trials)) +
                  " %) were left out because a draw was impossible (" + reasons +
                  "): the uncertainties are large for this setting, and the Monte Carlo values describe the "
                  "inputs' distribution cut to what is possible.");
  }
  return out;
}

// u_<key> (first order), u_mc_<key>, u_mc_<key>_interval, uncertainty_disagrees, and the
// Monte Carlo bookkeeping.
void AddUncertaintyKeys(const PropagationResult& p, nlohmann::ordered_json* j) {
  for (const PropagatedValue* q : p.Outputs()) {
    const std::string key = q->name;
    (*j)["u_" + key] = q->u_first_order;
    (*j)["u_mc_" + key] = q->u_monte_carlo;
    (*j)["u_mc_" + key + "_interval"] = {q->coverage_low, q->coverage_high};
  }
  (*j)["uncertainty_disagrees"] = p.disagrees;
  (*j)["mc_trials"] = p.trials;
  (*j)["mc_rejected_trials"] = p.rejected.total();
}

}  // namespace

namespace {
// The last guard before any output: every number of the result is finite. The inputs' ranges
// (RequireModelLength, the model's own rules) keep the known cases finite; a combination they
// miss is refused, naming what overflowed, rather than printed as inf or NaN.
void RequireFiniteResult(const ConversionResult& r) {
  const Scene& s = r.scene;
  std::vector<std::pair<const char*, double>> values = {
      {"theta", s.rails().theta}, {"alpha", s.rails().alpha}, {"x_max", s.x_max()}, {"x_low", s.x_low()}};
  if (s.x_eq()) values.push_back({"X", *s.x_eq()});
  for (const PathPoint& p : r.points) {
    values.push_back({"z at --at-x", p.z});
    values.push_back({"dz/dx at --at-x", p.dzdx});
    values.push_back({"R* at --at-x", p.r_star});
  }
  if (r.rest) {
    values.push_back({"x_rest", r.rest->high});
    values.push_back({"x_rest(-mu)", r.rest->low});
  }
  if (r.propagation)
    for (const PropagatedValue* q : r.propagation->Outputs()) {
      values.push_back({q->name, q->u_first_order});
      values.push_back({q->name, q->u_monte_carlo});
    }
  for (const auto& [name, v] : values)
    if (!std::isfinite(v))
      throw InputError("the setting", std::string(name) + " (or its uncertainty) is not a finite number for these "
                                                            "values: a length, angle or uncertainty is too extreme");
}
}  // namespace

ConversionResult Convert(const Configuration& configuration, const ConversionOptions& options) {
  ConversionResult r{configuration, configuration.MakeScene(), {}, options.mu, {}, {}, {}};
  for (double x : options.at_x) {
    try {
      r.points.push_back(r.scene.At(x));
    } catch (const InputError& e) {
      throw InputError("--at-x", e.rule());
    }
  }
  if (options.mu) {
    try {
      r.rest = r.scene.Rest(*options.mu);
    } catch (const InputError& e) {
      throw InputError("--mu", e.rule());
    }
  }
  if (configuration.HasUncertainty())
    r.propagation = Propagate(configuration.MakeUncertainRails(), configuration.MakeUncertainBody(),
                              configuration.rod_radius, options.propagation);
  if (options.verdict) r.verdict = Verdict(r, options);
  RequireFiniteResult(r);
  return r;
}

ConversionSummary Summarize(const ConversionResult& r) {
  const Scene& s = r.scene;
  ConversionSummary v;
  v.label = r.configuration.label;
  v.body = s.body().kind;
  v.theta = s.rails().theta;
  v.alpha = s.rails().alpha;
  v.phi = s.rails().HalfAngleBetweenRails();
  v.x_eq = s.x_eq();
  v.x_max = s.x_max();
  if (r.propagation && r.propagation->x_eq) {
    v.u_x_eq = r.propagation->x_eq->u_first_order;
    v.u_mc_x_eq = r.propagation->x_eq->u_monte_carlo;
  }
  v.rest = r.rest;
  v.theta0 = s.theta0();
  v.rolls_up = s.rolls_up();
  const auto crossbar = r.configuration.CrossbarDistance();
  v.x_eq_beyond_crossbar = crossbar && v.x_eq && *v.x_eq > *crossbar;
  v.uncertainty_disagrees = r.propagation && r.propagation->disagrees;
  return v;
}

nlohmann::ordered_json ToJson(const ConversionResult& r) {
  using nlohmann::ordered_json;
  const Scene& s = r.scene;
  const Configuration& c = r.configuration;
  ordered_json j;
  if (!c.label.empty()) j["label"] = c.label;
  j["body"] = s.body().Name();
  j["theta"] = s.rails().theta;
  j["alpha"] = s.rails().alpha;
  j["phi"] = s.rails().HalfAngleBetweenRails();
  if (const auto crossbar = c.CrossbarDistance()) j["L_horizontal"] = *crossbar;
  j["x_eq"] = s.x_eq() ? ordered_json(*s.x_eq()) : ordered_json(nullptr);
  j["z_eq"] = s.z_eq() ? ordered_json(*s.z_eq()) : ordered_json(nullptr);
  j["x_max"] = s.x_max();
  j["x_low"] = s.x_low();
  j["rolls_up"] = s.rolls_up();
  if (const auto crossbar = c.CrossbarDistance(); crossbar && s.x_eq())
    j["x_eq_beyond_crossbar"] = *s.x_eq() > *crossbar;
  if (s.cone()) {
    j["theta0"] = *s.theta0();
    j["theta0_fixed_phi"] = s.theta0_fixed_phi() ? ordered_json(*s.theta0_fixed_phi()) : ordered_json(nullptr);
    j["dzdx"] = -s.cone()->B();
  }
  if (!r.points.empty()) {
    ordered_json points = ordered_json::array();
    for (const PathPoint& p : r.points)
      points.push_back({{"x", p.x}, {"z", p.z}, {"dzdx", p.dzdx}, {"R_star", p.r_star}, {"x_M", p.x_contact}});
    j["points"] = points;
  }
  if (r.rest) {
    j["x_rest"] = r.rest->high;
    j["x_rest_low"] = r.rest->low;
  }
  if (s.cone() && r.mu) j["rests_everywhere"] = s.RestsEverywhere(*r.mu);
  if (r.propagation) AddUncertaintyKeys(*r.propagation, &j);
  j["verdict"] = r.verdict;
  return j;
}

}  // namespace uphill
