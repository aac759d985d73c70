// Scene: one body on one pair of rails (line rails or round rods): everything the converter
// reports, behind one interface that picks the cheapest exact model for the scene.
//
//   sphere or spheroid on line rails  -> SpheroidOnLineRails (closed form)
//   sphere on rods of radius r        -> closed form of a sphere of radius R + r on line rails,
//                                        R* and the contact scaled back to the real sphere
//   spheroid on rods                  -> SpheroidOnRods (the one numeric contact solve)
//   double cone on line rails         -> DoubleConeOnLineRails (closed form, straight path)
//   double cone on rods               -> refused (not modelled: say so rather than guess)
//
// Units: SI (metres, radians). Every method documents its domain; outside it, InputError.
#pragma once

#include <optional>
#include <variant>

#include "model/body.hpp"
#include "model/double_cone_on_line_rails.hpp"
#include "model/rails.hpp"
#include "model/spheroid_on_line_rails.hpp"
#include "model/spheroid_on_rods.hpp"

namespace uphill {

// The centre at horizontal position x: height z, slope dz/dx, distance R* from the centre to
// the instantaneous axis (through both true contacts), and the contact point's x on the body.
struct PathPoint {
  double x = 0, z = 0, dzdx = 0, r_star = 0, x_contact = 0;
};

// Rest band of the rolling-resistance model (at rest where |z'(x)| ≤ μ): [low, high] =
// [x_rest(−μ), x_rest(μ)]. low may be negative (the band reaches O).
struct RestBand {
  double low = 0, high = 0;
};

class Scene {
 public:
  // Throws InputError when the body cannot rest on both rails (double cone with
  // 1 + tan²θ − (R/h)²tan²(α/2) ≤ 0) or when the scene is not modelled (cone on rods).
  Scene(const Body& body, const Rails& rails, double rod_radius = 0.0);

  const Body& body() const { return body_; }
  const Rails& rails() const { return rails_; }
  double rod_radius() const { return rod_radius_; }

  // The unstable equilibrium X (the maximum of z) and the height there; none for the cone.
  std::optional<double> x_eq() const;
  std::optional<double> z_eq() const;
  // Fall-off: sphere/spheroid where the contact is level with the centre (z' → −∞); double
  // cone where the contact reaches the apex (x_fall = h·cot(α/2), R* → 0).
  double x_max() const;
  // Smallest x the path is defined for (contact at the rails' start, t = 0).
  double x_low() const;
  // x_max − x_eq without cancellation (sphere/spheroid).
  std::optional<double> FallOffMargin() const;
  // True if released at rest beyond X (anywhere, for the cone) the body rolls away from O
  // while its centre descends. Always true for sphere and spheroid; θ < θ0 for the cone.
  bool rolls_up() const;
  // The path at x; throws InputError unless x_low ≤ x ≤ x_max.
  PathPoint At(double x) const;
  // Rest band for rolling-resistance coefficient mu ≥ 0 (sphere/spheroid). For the double cone
  // the slope is constant: see RestsEverywhere.
  std::optional<RestBand> Rest(double mu) const;
  bool RestsEverywhere(double mu) const;
  // The double cone's closed form, or nullptr for other bodies.
  const DoubleConeOnLineRails<double>* cone() const;
  // Double cone: critical inclination at fixed α, tanθ0 = (R/h)·tan(α/2).
  std::optional<double> theta0() const;
  // Double cone: critical inclination at the same 3-D opening 2φ: asin(tanφ·R/h), none when
  // tanφ·R/h ≥ 1 (then it rolls up at every inclination).
  std::optional<double> theta0_fixed_phi() const;
  // 1 + I/(m·R*²) at x: the factor in ½·m·v_C²·(1 + I/(m R*²)) = m·g·(z(x0) − z(x)).
  double KineticFactor(double x) const;

 private:
  struct SphereOnRods {
    SpheroidOnLineRails<double> enlarged;  // sphere of radius R + r on the rod axes
    double shrink;                          // R/(R + r)
  };
  using Path = std::variant<SpheroidOnLineRails<double>, SphereOnRods, SpheroidOnRods,
                            DoubleConeOnLineRails<double>>;
  static Path MakePath(const Body& body, const Rails& rails, double rod_radius);

  Body body_;
  Rails rails_;
  double rod_radius_;
  Path path_;
};

}  // namespace uphill
