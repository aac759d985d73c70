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

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "model/propagation.hpp"

namespace uphill {

// The Monte Carlo of every front end's conversion (`uphill convert`, Python's convert_setting and
// convert_batch_file): 10^6 trials give u to about 0.1 % (model/propagation.hpp), and one fixed
// seed makes the same input give the same numbers in each.
inline constexpr std::uint64_t kConvertMonteCarloTrials = 1'000'000;
inline constexpr std::uint64_t kConvertSeed = 20261121;

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

// The values of a result that the table and the CSV of `uphill convert` show (SI: m, rad): what a
// batch hands on per row when nothing else is printed (convert_batch.hpp, BatchDetail::kSummary).
struct ConversionSummary {
  std::string label;
  BodyKind body = BodyKind::kSpheroid;
  double theta = 0.0, alpha = 0.0, phi = 0.0;
  std::optional<double> x_eq;                // none for the double cone
  double x_max = 0.0;                        // x_fall for the double cone
  std::optional<double> u_x_eq, u_mc_x_eq;   // first-order and Monte Carlo u(x_eq)
  std::optional<RestBand> rest;              // with mu
  std::optional<double> theta0;              // double cone
  bool rolls_up = true;
  bool x_eq_beyond_crossbar = false;         // apparatus input with X > L (horizontal)
  bool uncertainty_disagrees = false;        // first order and Monte Carlo differ by > 5 %
};
ConversionSummary Summarize(const ConversionResult& result);

nlohmann::ordered_json ToJson(const ConversionResult& result);

}  // namespace uphill
