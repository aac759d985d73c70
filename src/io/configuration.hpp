// Configuration: one apparatus setting as a person enters it — a body with its dimensions, the
// rails given either by the crossbar measurements (L, H, D) or by the angles (θ, α), an optional
// rod diameter, and optional standard uncertainties — parsed from named text fields with units.
//
// The same names serve the command line (`--L 1165mm`) and CSV columns (`L_mm` with plain
// numbers, or `L` with a unit in every cell):
//   body            sphere | spheroid | double-cone
//   R               sphere radius; double-cone base radius              (length)
//   a, b            spheroid semi-axes: a across (x, z), b along the rolling axis (length)
//   h               double-cone half-length                              (length)
//   L, H, D         crossbar distance, height, rail separation           (length)
//   theta, alpha    inclination, divergence angle (instead of L, H, D)   (angle)
//   rod_diameter    diameter of round rods; 0 or absent: line rails      (length)
//   u_<name>        standard uncertainty of <name>, same dimension        (e.g. u_D_mm)
//   L_convention    horizontal (default) | along-rail
//   label           free text carried to the output
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/units.hpp"
#include "model/body.hpp"
#include "model/propagation.hpp"
#include "model/rails.hpp"
#include "model/scene.hpp"

namespace uphill {

struct Configuration {
  std::string label;
  BodyKind body_kind = BodyKind::kSpheroid;
  Uncertain across;  // R (sphere, cone) or a (spheroid)
  Uncertain along;   // R (sphere), b (spheroid), h (cone)
  bool from_apparatus = true;
  Uncertain L, H, D;  // when from_apparatus
  LConvention convention = LConvention::kHorizontal;
  Uncertain theta, alpha;  // when !from_apparatus
  Uncertain rod_radius;    // half the rod diameter

  bool HasUncertainty() const;
  Body MakeBody() const;    // throws InputError
  Rails MakeRails() const;  // throws InputError
  Scene MakeScene() const;  // throws InputError, also for positions beyond model/input_ranges.hpp
  // The inputs with their uncertainties, for Propagate (model/propagation.hpp).
  UncertainRails MakeUncertainRails() const;
  UncertainBody MakeUncertainBody() const;
  // Horizontal distance O→crossbar (m) when given by L, H, D.
  std::optional<double> CrossbarDistance() const;
};

// Where the fields come from. Lookup(name) returns the text and the unit implied by its
// source (a CSV header suffix), or nullopt when absent. Context(name) names the field for
// messages: "--L" or "runs.csv, row 4, column L_mm".
struct FieldSource {
  struct Field {
    std::string text;
    std::string default_unit;
    // A default from elsewhere (flags under a batch CSV, an experiment's default uncertainties):
    // an uncertainty given this way may go unused (a u_L default for a row given by angles).
    // Given for this configuration itself, an uncertainty of a quantity it does not use is an
    // error: it would be silently ignored.
    bool is_default = false;
  };
  std::function<std::optional<Field>(const std::string& name)> lookup;
  std::function<std::string(const std::string& name)> context;
};

// Parses a configuration. Throws InputError whose quantity is the field's context and whose
// rule says what is wrong (missing field, bad number or unit, conflicting L/H/D and θ/α, a
// dimension that does not belong to the body, invalid geometry).
Configuration ParseConfiguration(const FieldSource& source);

// The field names ParseConfiguration understands (for "unknown column" checks).
const std::vector<std::string>& ConfigurationFieldNames();

// For batches whose rows differ only in numbers (io's batch conversion): the dimension of a
// numeric field (R, a, b, h, L, H, D, theta, alpha, rod_diameter and their u_<name>), or
// nullopt for the others (body, label, L_convention).
std::optional<Dimension> NumericFieldDimension(std::string_view name);
// Sets numeric field `name` of a configuration that ParseConfiguration returned to the value
// `si` (SI units), exactly as ParseConfiguration would have read it from a row that differs only
// there. False when the field has no place in this configuration or the value is one that
// ParseConfiguration refuses on reading (a value outside its range in model/input_ranges.hpp):
// parse that row instead. The geometry is not checked here
// (Configuration::MakeScene does it).
bool SetNumericField(Configuration& configuration, std::string_view name, double si);

// The same with the field's name looked up once (a batch sets the same columns on millions of
// rows): FindNumericField(name) is nullopt where NumericFieldDimension is, and
// SetNumericField(c, *FindNumericField(name), si) does exactly what SetNumericField(c, name, si) does.
struct NumericField {
  enum class Target { kR, kA, kB, kConeH, kL, kH, kD, kTheta, kAlpha, kRodDiameter };
  Target target = Target::kL;
  bool uncertainty = false;  // u_<name>
  bool length = false;       // Dimension::kLength
};
std::optional<NumericField> FindNumericField(std::string_view name);
bool SetNumericField(Configuration& configuration, const NumericField& field, double si);

}  // namespace uphill
