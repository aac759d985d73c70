#include "motion/motion.hpp"

#include <sstream>

#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "internal/motion_engine.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace internal {

bool IsEllipse(const Scene& scene) {
  const BodyKind k = scene.body().kind;
  return k == BodyKind::kSphere || (k == BodyKind::kSpheroid && scene.rod_radius() == 0.0);
}

EllipseCoordinate MakeEllipse(const Scene& scene) {
  const Body& body = scene.body();
  const Rails& rails = scene.rails();
  const double r = scene.rod_radius();
  if (body.kind == BodyKind::kSphere) {
    EllipseCoordinate e(body.across + r, body.across + r, rails.tan_theta, rails.tan_half_alpha,
                        body.InertiaFactor());
    e.set_shrink(body.across / (body.across + r));
    return e;
  }
  return EllipseCoordinate(body.across, body.along, rails.tan_theta, rails.tan_half_alpha, body.InertiaFactor());
}

}  // namespace internal

std::string EventName(MotionEventKind kind) {
  switch (kind) {
    case MotionEventKind::kFallOff: return "falls off";
    case MotionEventKind::kReachesO: return "reaches O";
    case MotionEventKind::kTurningPoint: return "turning point";
    case MotionEventKind::kRest: return "comes to rest";
    case MotionEventKind::kPosition: return "position";
  }
  return "?";
}

Motion::Motion(const Scene& scene, double x0, const MotionOptions& o) {
  const double lo = scene.x_low(), hi = scene.x_max();
  const bool cone = scene.cone() != nullptr;
  if (!std::isfinite(x0) || x0 < lo || x0 > hi || (cone && x0 >= hi))
    throw InputError("x0", "must lie on the path, in [" + ExactText(lo) + ", " + ExactText(hi) + (cone ? ")" : "]") +
                               " m (got " + ExactText(x0) + " m)");
  RequireSpeed("v0", o.v0);
  RequireGravity("g", o.g);
  RequireRollingResistance("mu", o.mu);
  if (!(o.tolerance >= 1e-15 && o.tolerance <= 1e-2))
    throw InputError("tolerance", "must lie in [1e-15, 1e-2] (got " + ExactText(o.tolerance) + ")");
  if (o.method == MotionMethod::kQuadrature && o.mu > 0.0)
    throw InputError("mu", "rolling resistance needs the ode method (energy is not conserved)");
  engine_ = o.method == MotionMethod::kQuadrature ? internal::MakeQuadratureEngine(scene, x0, o)
                                                  : internal::MakeOdeEngine(scene, x0, o);
}

Motion::~Motion() = default;
Motion::Motion(Motion&&) noexcept = default;
Motion& Motion::operator=(Motion&&) noexcept = default;

const Scene& Motion::scene() const { return engine_->scene(); }
double Motion::x0() const { return engine_->x0(); }
int Motion::direction() const { return engine_->direction(); }
const std::vector<MotionEvent>& Motion::events() const { return engine_->events(); }
double Motion::end_time() const { return engine_->end_time(); }
double Motion::TimeAt(double x) const { return engine_->TimeAt(x); }
MotionEvent Motion::PositionEvent(double x) const { return {MotionEventKind::kPosition, TimeAt(x), x}; }
MotionSample Motion::At(double t) const { return engine_->At(t); }
MotionSample Motion::AtPosition(double x) const {
  const double t = engine_->TimeAt(x);
  if (!std::isfinite(t)) throw InputError("x", "the centre never reaches x = " + ExactText(x) + " m");
  return engine_->AtPosition(x);
}

}  // namespace uphill
