// Body: the rolling body, uniform density (docs/physics.md "Bodies").
//
//   sphere       radius R                        I_y = 2/5·m·R²
//   spheroid     semi-axes a (in x and z), b      I_y = 2/5·m·a²   (b along y, the rolling axis)
//   double cone  base radius R, half-length h     I_y = 3/10·m·R²  (axis along y)
//
// All lengths in metres. The body's symmetry axis stays parallel to y, so the motion has one
// degree of freedom: the centre's x.
#pragma once

#include <string>

namespace uphill {

enum class BodyKind { kSphere, kSpheroid, kDoubleCone };

struct Body {
  BodyKind kind = BodyKind::kSphere;
  double across = 0.0;  // half-size across the rolling axis: R (sphere, cone) or a (spheroid)
  double along = 0.0;   // half-size along the rolling axis y: R (sphere), b (spheroid), h (cone)

  // Factories validate their arguments (finite and > 0) and throw InputError naming them.
  static Body Sphere(double R);
  static Body Spheroid(double a, double b);
  static Body DoubleCone(double R, double h);

  // I_y / (m·across²): 2/5 for sphere and spheroid, 3/10 for the double cone.
  double InertiaFactor() const;
  // "sphere", "spheroid", "double-cone" (the CLI's --body values).
  std::string Name() const;
};

// Parses "sphere", "spheroid", "double-cone" (also "double_cone", "cone"); throws InputError.
BodyKind ParseBodyKind(const std::string& name);

}  // namespace uphill
