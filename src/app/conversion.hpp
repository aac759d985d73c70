// Conversion: the use case behind `uphill convert` (docs/convert.md) for one configuration —
// the scene, points on the path, the rest band, the propagated uncertainties and plain-language
// verdicts — and the JSON form of a result (the stable machine interface of docs/convert.md,
// "JSON output"). A batch of configurations: convert_batch.hpp.
//
// All numbers SI (m, rad). Keys: theta, alpha, phi, x_eq (null for the double cone), z_eq,
// x_max (fall-off; for the double cone x_fall), x_low, rolls_up, theta0 and theta0_fixed_phi
// (double cone), L_horizontal and x_eq_beyond_crossbar (apparatus input), points (with at_x),
// x_rest, x_rest_low (with mu; rests_everywhere for the double cone), u_<key> and u_mc_<key>
// (inputs with uncertainties), verdict.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "model/propagation.hpp"

namespace uphill {

struct ConversionOptions {
  std::optional<double> mu;       // rolling-resistance coefficient for the rest band
  std::vector<double> at_x;       // positions (m) at which to report the path
  PropagationOptions propagation;  // Monte Carlo trials and seed (model/propagation.hpp)
  std::string length_unit = "mm";  // for the verdict sentences only
  bool verdict = true;             // write the verdict sentences (only the JSON output has them)
};

struct ConversionResult {
  Configuration configuration;
  Scene scene;
  std::vector<PathPoint> points;
  std::optional<double> mu;
  std::optional<RestBand> rest;
  std::optional<PropagationResult> propagation;  // when an input carries an uncertainty
  std::vector<std::string> verdict;        // plain-language sentences
};

// Throws InputError (quantity "--at-x" or "--mu") for a position off the path or a bad μ.
ConversionResult Convert(const Configuration& configuration, const ConversionOptions& options);

nlohmann::ordered_json ToJson(const ConversionResult& result);

}  // namespace uphill
