#include "propagation_problem.hpp"

#include <cmath>
#include <string>

#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "model/scene.hpp"

namespace uphill::internal {
namespace {

void RequireUncertainty(InputQuantity q, BodyKind body, double u) {
  if (!std::isfinite(u) || u < 0.0)
    throw InputError(std::string("u(") + InputName(q, body) + ")",
                     "must be a finite number >= 0 (got " + ExactText(u) + ")");
}

}  // namespace

Problem MakeProblem(const UncertainRails& rails, const UncertainBody& body, Uncertain rod) {
  Problem p;
  p.given = rails.given;
  p.convention = rails.convention;
  p.body = body.kind;
  auto set = [&](InputQuantity q, Uncertain x) {
    RequireUncertainty(q, body.kind, x.u);
    p.present[Index(q)] = true;
    p.value[Index(q)] = x.value;
    p.u[Index(q)] = x.u;
  };
  if (rails.given == UncertainRails::Given::kApparatus) {
    set(InputQuantity::kL, rails.L);
    set(InputQuantity::kH, rails.H);
    set(InputQuantity::kD, rails.D);
  } else {
    set(InputQuantity::kTheta, rails.theta);
    set(InputQuantity::kAlpha, rails.alpha);
  }
  set(InputQuantity::kAcross, body.across);
  if (body.kind != BodyKind::kSphere) set(InputQuantity::kAlong, body.along);
  RequireUncertainty(InputQuantity::kRodRadius, body.kind, rod.u);
  // The model's own checks, with its messages: values finite and in range, the scene modelled.
  const Rails nominal_rails =
      rails.given == UncertainRails::Given::kApparatus
          ? Rails::FromApparatus(rails.L.value, rails.H.value, rails.D.value, rails.convention)
          : Rails::FromAngles(rails.theta.value, rails.alpha.value);
  const Body nominal_body = body.kind == BodyKind::kSphere     ? Body::Sphere(body.across.value)
                            : body.kind == BodyKind::kSpheroid ? Body::Spheroid(body.across.value,
                                                                                body.along.value)
                                                               : Body::DoubleCone(body.across.value,
                                                                                  body.along.value);
  const Scene scene(nominal_body, nominal_rails, rod.value);
  (void)scene;
  p.rods = rod.value > 0.0;
  if (p.rods) {
    set(InputQuantity::kRodRadius, rod);
  } else if (rod.u != 0.0) {
    throw InputError("u(r)", "must be 0 for line rails (r = 0); give r > 0 for round rods (got " +
                                 ExactText(rod.u) + ")");
  }
  return p;
}

void ValidateOptions(const PropagationOptions& o) {
  if (o.trials != 0 && o.trials < 100)
    throw InputError("trials", "must be 0 (first order only) or >= 100 (got " +
                                   std::to_string(o.trials) + ")");
  if (!(o.coverage > 0.0 && o.coverage < 1.0))
    throw InputError("coverage", "must lie in (0, 1) (got " + ExactText(o.coverage) + ")");
  if (!(o.disagreement_tolerance > 0.0) || !std::isfinite(o.disagreement_tolerance))
    throw InputError("disagreement tolerance",
                     "must be a finite number > 0 (got " + ExactText(o.disagreement_tolerance) + ")");
}

bool HasOutput(BodyKind body, int slot) {
  if (slot == kOutXEq) return body != BodyKind::kDoubleCone;
  if (slot == kOutTheta0) return body == BodyKind::kDoubleCone;
  return true;
}

}  // namespace uphill::internal
