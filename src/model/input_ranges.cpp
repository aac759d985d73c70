#include "model/input_ranges.hpp"

#include <cmath>
#include <numbers>

#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "model/scene.hpp"

namespace uphill {
namespace {

// A value for a message: 6 significant digits, as a person reads it back.
std::string Shown(double v) { return Printf("%.6g", v); }

[[noreturn]] void Refuse(const std::string& quantity, const std::string& range, double value, const char* unit,
                         const char* why = "") {
  throw InputError(quantity, "must " + range + " (got " + Shown(value) + (*unit ? " " : "") + unit + ")" + why);
}

bool InLengthRange(double metres) {
  const double size = std::abs(metres);
  return size >= kShortestModelLength && size <= kLongestModelLength;  // false for NaN
}

constexpr const char* kLengthWhy =
    ": the model is meant for lengths of an apparatus, and its numbers overflow far outside them";

}  // namespace

void RequireModelLength(const std::string& quantity, double metres) {
  if (metres != 0.0 && !InLengthRange(metres)) Refuse(quantity, "lie between 1 nm and 1000 km, or be 0", metres, "m", kLengthWhy);
}

void RequirePositiveLength(const std::string& quantity, double metres) {
  if (!(metres > 0.0 && InLengthRange(metres))) Refuse(quantity, "be > 0, between 1 nm and 1000 km", metres, "m", kLengthWhy);
}

void RequireLengthUncertainty(const std::string& quantity, double metres) {
  if (!(metres == 0.0 || (metres > 0.0 && InLengthRange(metres))))
    Refuse(quantity, "be >= 0: 0, or between 1 nm and 1000 km", metres, "m", kLengthWhy);
}

void RequireAngleUncertainty(const std::string& quantity, double radians) {
  if (!(radians >= 0.0 && radians <= std::numbers::pi))
    Refuse(quantity, "be >= 0 and at most pi rad (180 deg)", radians, "rad", ": a wider spread covers every direction");
}

void RequireGravity(const std::string& quantity, double g) {
  if (!(g >= kSmallestGravity && g <= kLargestGravity))
    Refuse(quantity, "be > 0, between 0.001 and 1000 m/s2", g, "m/s2",
           ": the motion's times scale as 1/sqrt(g) and lose every digit far outside it");
}

void RequireSpeed(const std::string& quantity, double v) {
  if (!(std::abs(v) <= kFastestSpeed))
    Refuse(quantity, "be at most 1000 m/s in size", v, "m/s", ": far beyond a throw the integrator's steps vanish");
}

void RequireRollingResistance(const std::string& quantity, double mu) {
  if (!(mu >= 0.0 && mu <= kLargestRollingResistance)) Refuse(quantity, "lie between 0 and 10", mu, "");
}

void RequireMonteCarloTrials(const std::string& quantity, double trials) {
  if (!(trials >= kFewestTrials && trials <= kMostTrials)) Refuse(quantity, "lie between 100 and 100000000", trials, "");
}

void RequireSceneInRange(const Scene& scene) {
  RequireFiniteResult("theta", scene.rails().theta);
  RequireFiniteResult("alpha", scene.rails().alpha);
  RequireFiniteResult("x_low", scene.x_low());
  const auto position = [](const char* name, double x) {
    RequireFiniteResult(name, x);
    if (std::abs(x) > kLongestModelLength)
      throw InputError("the setting", std::string(name) + " = " + Shown(x) +
                                          " m lies beyond 1000 km from O: an angle or a ratio of lengths is too extreme");
  };
  if (const auto x_eq = scene.x_eq()) position("X", *x_eq);
  if (const auto z_eq = scene.z_eq()) RequireFiniteResult("z at X", *z_eq);
  position(scene.cone() ? "x_fall" : "x_max", scene.x_max());
}

void RequireFiniteResult(const std::string& what, double value) {
  if (!std::isfinite(value))
    throw InputError("the setting", what + " (or its uncertainty) is not a finite number for these values: a length, "
                                           "angle or uncertainty is too extreme");
}

}  // namespace uphill
