#include "model/body.hpp"

#include "model/input_error.hpp"

namespace uphill {

Body Body::Sphere(double R) {
  RequirePositiveFinite("R", R);
  return Body{BodyKind::kSphere, R, R};
}

Body Body::Spheroid(double a, double b) {
  RequirePositiveFinite("a", a);
  RequirePositiveFinite("b", b);
  return Body{BodyKind::kSpheroid, a, b};
}

Body Body::DoubleCone(double R, double h) {
  RequirePositiveFinite("R", R);
  RequirePositiveFinite("h", h);
  return Body{BodyKind::kDoubleCone, R, h};
}

double Body::InertiaFactor() const { return kind == BodyKind::kDoubleCone ? 0.3 : 0.4; }

std::string Body::Name() const {
  switch (kind) {
    case BodyKind::kSphere: return "sphere";
    case BodyKind::kSpheroid: return "spheroid";
    case BodyKind::kDoubleCone: return "double-cone";
  }
  return "unknown";
}

BodyKind ParseBodyKind(const std::string& name) {
  if (name == "sphere") return BodyKind::kSphere;
  if (name == "spheroid") return BodyKind::kSpheroid;
  if (name == "double-cone" || name == "double_cone" || name == "cone") return BodyKind::kDoubleCone;
  throw InputError("body", "unknown body '" + name + "' (accepted: sphere, spheroid, double-cone)");
}

}  // namespace uphill
