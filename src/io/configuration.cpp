#include "io/configuration.hpp"

#include <algorithm>
#include <cmath>

#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"

namespace uphill {
namespace {

struct FieldSpec {
  const char* name;
  Dimension dimension;
};

constexpr FieldSpec kUncertainFields[] = {
    {"R", Dimension::kLength},     {"a", Dimension::kLength},     {"b", Dimension::kLength},
    {"h", Dimension::kLength},     {"L", Dimension::kLength},     {"H", Dimension::kLength},
    {"D", Dimension::kLength},     {"theta", Dimension::kAngle},  {"alpha", Dimension::kAngle},
    {"rod_diameter", Dimension::kLength},
};

// The range of a numeric field: a length of the model, or a standard uncertainty of a length or
// an angle (model/input_ranges.hpp).
void RequireFieldRange(const std::string& name, double si, bool length, bool uncertainty) {
  if (uncertainty) {
    if (si < 0.0) throw InputError(name, "must be >= 0");  // the sign is the rule a negative one breaks
    if (length) RequireLengthUncertainty(name, si);
    else RequireAngleUncertainty(name, si);
  } else if (length) {
    RequireModelLength(name, si);
  }
}

class Reader {
 public:
  explicit Reader(const FieldSource& source) : source_(source) {}

  bool Has(const std::string& name) const { return source_.lookup(name).has_value(); }

  std::string Text(const std::string& name) const {
    const auto field = source_.lookup(name);
    return field ? field->text : std::string();
  }

  std::optional<Uncertain> Get(const std::string& name, Dimension dimension) const {
    const auto field = source_.lookup(name);
    if (!field) return std::nullopt;
    used_.push_back(name);
    Uncertain m;
    m.value = Parse(name, *field, dimension, false);
    if (const auto uf = source_.lookup("u_" + name)) m.u = Parse("u_" + name, *uf, dimension, true);
    return m;
  }

  Uncertain Require(const std::string& name, Dimension dimension, const std::string& why) const {
    auto m = Get(name, dimension);
    if (!m) throw InputError(source_.context(name), "is missing (" + why + ")");
    return *m;
  }

  void Forbid(const std::string& name, const std::string& why) const {
    if (Has(name)) throw InputError(source_.context(name), why);
  }

  std::string Context(const std::string& name) const { return source_.context(name); }

  // An uncertainty given for this configuration of a quantity it does not use (u_L with the
  // angles, u_b for a sphere) would be silently ignored: refused, naming it.
  void RefuseUnusedUncertainties(const std::string& what_is_used) const {
    for (const FieldSpec& f : kUncertainFields) {
      if (std::find(used_.begin(), used_.end(), f.name) != used_.end()) continue;
      const auto u = source_.lookup(std::string("u_") + f.name);
      if (u && !u->is_default)
        throw InputError(source_.context(std::string("u_") + f.name),
                         std::string("is the uncertainty of ") + f.name + ", which this setting does not use (" +
                             what_is_used + ")");
    }
  }

 private:
  // The value of a field, in its range (model/input_ranges.hpp); an uncertainty's range when
  // `uncertainty`. Angles' own range is the model's (Rails::FromAngles).
  double Parse(const std::string& name, const FieldSource::Field& field, Dimension dimension, bool uncertainty) const {
    try {
      const double value = ParseQuantity(field.text, dimension, name, field.default_unit);
      RequireFieldRange(name, value, dimension == Dimension::kLength, uncertainty);
      return value;
    } catch (const InputError& e) {
      throw InputError(source_.context(name), e.rule());
    }
  }

  const FieldSource& source_;
  mutable std::vector<std::string> used_;  // the quantities read
};

}  // namespace

bool Configuration::HasUncertainty() const {
  for (const Uncertain* m : {&across, &along, &L, &H, &D, &theta, &alpha, &rod_radius})
    if (m->u > 0.0) return true;
  return false;
}

Body Configuration::MakeBody() const {
  switch (body_kind) {
    case BodyKind::kSphere: return Body::Sphere(across.value);
    case BodyKind::kSpheroid: return Body::Spheroid(across.value, along.value);
    case BodyKind::kDoubleCone: return Body::DoubleCone(across.value, along.value);
  }
  throw InputError("body", "unknown body kind");
}

Rails Configuration::MakeRails() const {
  if (from_apparatus) return Rails::FromApparatus(L.value, H.value, D.value, convention);
  return Rails::FromAngles(theta.value, alpha.value);
}

Scene Configuration::MakeScene() const {
  Scene scene(MakeBody(), MakeRails(), rod_radius.value);
  RequireSceneInRange(scene);
  return scene;
}

UncertainRails Configuration::MakeUncertainRails() const {
  if (from_apparatus) return UncertainRails::Apparatus(L, H, D, convention);
  return UncertainRails::Angles(theta, alpha);
}

UncertainBody Configuration::MakeUncertainBody() const {
  switch (body_kind) {
    case BodyKind::kSphere: return UncertainBody::Sphere(across);
    case BodyKind::kSpheroid: return UncertainBody::Spheroid(across, along);
    case BodyKind::kDoubleCone: return UncertainBody::DoubleCone(across, along);
  }
  throw InputError("body", "unknown body kind");
}

std::optional<double> Configuration::CrossbarDistance() const {
  if (!from_apparatus) return std::nullopt;
  return HorizontalDistance(L.value, H.value, D.value, convention);
}

const std::vector<std::string>& ConfigurationFieldNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n{"body", "label", "L_convention"};
    for (const auto& f : kUncertainFields) {
      n.push_back(f.name);
      n.push_back(std::string("u_") + f.name);
    }
    return n;
  }();
  return names;
}

Configuration ParseConfiguration(const FieldSource& source) {
  const Reader in(source);
  Configuration c;
  c.label = in.Text("label");
  if (!in.Has("body")) throw InputError(source.context("body"), "is missing (sphere, spheroid or double-cone)");
  try {
    c.body_kind = ParseBodyKind(in.Text("body"));
  } catch (const InputError& e) {
    throw InputError(source.context("body"), e.rule());
  }
  switch (c.body_kind) {
    case BodyKind::kSphere:
      c.across = c.along = in.Require("R", Dimension::kLength, "the sphere's radius");
      for (const char* f : {"a", "b", "h"}) in.Forbid(f, "does not apply to a sphere (give R)");
      break;
    case BodyKind::kSpheroid:
      c.across = in.Require("a", Dimension::kLength, "the semi-axis across the rails, in x and z");
      c.along = in.Require("b", Dimension::kLength, "the semi-axis along the rolling axis y");
      for (const char* f : {"R", "h"}) in.Forbid(f, "does not apply to a spheroid (give a and b)");
      break;
    case BodyKind::kDoubleCone:
      c.across = in.Require("R", Dimension::kLength, "the double cone's base radius");
      c.along = in.Require("h", Dimension::kLength, "the double cone's half-length");
      for (const char* f : {"a", "b"}) in.Forbid(f, "does not apply to a double cone (give R and h)");
      break;
  }
  const bool has_lhd = in.Has("L") || in.Has("H") || in.Has("D");
  const bool has_angles = in.Has("theta") || in.Has("alpha");
  if (has_lhd && has_angles)
    throw InputError(source.context(in.Has("theta") ? "theta" : "alpha"),
                     "give either the crossbar measurements L, H, D or the angles theta, alpha, not both");
  c.from_apparatus = !has_angles;
  if (c.from_apparatus) {
    c.L = in.Require("L", Dimension::kLength, "horizontal distance from O to the crossbar");
    c.H = in.Require("H", Dimension::kLength, "height of the rails at the crossbar");
    c.D = in.Require("D", Dimension::kLength, "rail separation at the crossbar");
    const std::string convention = in.Text("L_convention");
    if (convention == "along-rail" || convention == "along_rail") {
      c.convention = LConvention::kAlongRail;
    } else if (!convention.empty() && convention != "horizontal") {
      throw InputError(source.context("L_convention"),
                       "must be 'horizontal' or 'along-rail' (got '" + convention + "')");
    }
  } else {
    c.theta = in.Require("theta", Dimension::kAngle, "inclination of the rails");
    c.alpha = in.Require("alpha", Dimension::kAngle, "divergence angle of the rails");
  }
  if (auto rod = in.Get("rod_diameter", Dimension::kLength)) {
    c.rod_radius = Uncertain{rod->value / 2, rod->u / 2};
  }
  in.RefuseUnusedUncertainties(std::string(c.from_apparatus ? "the rails are given as L, H, D" : "the rails are given as theta, alpha") +
                               "; the body as " + (c.body_kind == BodyKind::kSphere ? "R" : c.body_kind == BodyKind::kSpheroid ? "a, b" : "R, h") +
                               (c.rod_radius.value > 0 || in.Has("rod_diameter") ? "; rods" : "; line rails"));
  // Validate the geometry now, naming the field the model complains about.
  try {
    c.MakeScene();
  } catch (const InputError& e) {
    const std::string& q = e.quantity();
    const bool is_field = std::any_of(std::begin(kUncertainFields), std::end(kUncertainFields),
                                      [&](const FieldSpec& f) { return q == f.name; });
    const std::string name = q == "rod radius" ? "rod_diameter" : is_field ? q : "body";
    throw InputError(source.context(name), e.rule());
  }
  return c;
}

std::optional<Dimension> NumericFieldDimension(std::string_view name) {
  if (name.rfind("u_", 0) == 0) name.remove_prefix(2);
  for (const FieldSpec& f : kUncertainFields)
    if (name == f.name) return f.dimension;
  return std::nullopt;
}

std::optional<NumericField> FindNumericField(std::string_view name) {
  const auto dimension = NumericFieldDimension(name);
  if (!dimension) return std::nullopt;
  NumericField f;
  f.length = *dimension == Dimension::kLength;
  f.uncertainty = name.rfind("u_", 0) == 0;
  if (f.uncertainty) name.remove_prefix(2);
  using T = NumericField::Target;
  f.target = name == "R" ? T::kR : name == "a" ? T::kA : name == "b" ? T::kB : name == "h" ? T::kConeH
           : name == "L" ? T::kL : name == "H" ? T::kH : name == "D" ? T::kD : name == "theta" ? T::kTheta
           : name == "alpha" ? T::kAlpha : T::kRodDiameter;
  if (f.target == T::kRodDiameter && name != "rod_diameter") return std::nullopt;
  return f;
}

bool SetNumericField(Configuration& c, const NumericField& field, double si) {
  // A value outside its range (model/input_ranges.hpp): the full parse names the cell.
  try {
    RequireFieldRange("", si, field.length, field.uncertainty);
  } catch (const InputError&) {
    return false;
  }
  const auto set = [&](Uncertain& m, double v) { (field.uncertainty ? m.u : m.value) = v; };
  using T = NumericField::Target;
  switch (field.target) {
    case T::kR:
      if (c.body_kind == BodyKind::kSpheroid) return false;
      set(c.across, si);
      if (c.body_kind == BodyKind::kSphere) set(c.along, si);
      return true;
    case T::kA:
    case T::kB:
      if (c.body_kind != BodyKind::kSpheroid) return false;
      set(field.target == T::kA ? c.across : c.along, si);
      return true;
    case T::kConeH:
      if (c.body_kind != BodyKind::kDoubleCone) return false;
      set(c.along, si);
      return true;
    case T::kL:
    case T::kH:
    case T::kD:
      if (!c.from_apparatus) return false;
      set(field.target == T::kL ? c.L : field.target == T::kH ? c.H : c.D, si);
      return true;
    case T::kTheta:
    case T::kAlpha:
      if (c.from_apparatus) return false;
      set(field.target == T::kTheta ? c.theta : c.alpha, si);
      return true;
    case T::kRodDiameter:
      set(c.rod_radius, si / 2);
      return true;
  }
  return false;
}

bool SetNumericField(Configuration& c, std::string_view name, double si) {
  const std::optional<NumericField> field = FindNumericField(name);
  return field && SetNumericField(c, *field, si);
}

}  // namespace uphill
