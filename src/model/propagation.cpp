#include "model/propagation.hpp"

#include <cmath>
#include <limits>

#include "internal/first_order.hpp"
#include "internal/monte_carlo.hpp"
#include "internal/propagation_problem.hpp"

namespace uphill {
namespace {

using namespace internal;

void Flag(PropagatedValue& v, double tolerance) {
  v.disagrees = std::abs(v.u_first_order - v.u_monte_carlo) > tolerance * v.u_monte_carlo;
}

}  // namespace

const char* InputName(InputQuantity quantity, BodyKind body) {
  switch (quantity) {
    case InputQuantity::kL: return "L";
    case InputQuantity::kH: return "H";
    case InputQuantity::kD: return "D";
    case InputQuantity::kTheta: return "theta";
    case InputQuantity::kAlpha: return "alpha";
    case InputQuantity::kAcross: return body == BodyKind::kSpheroid ? "a" : "R";
    case InputQuantity::kAlong: return body == BodyKind::kDoubleCone ? "h" : "b";
    case InputQuantity::kRodRadius: return "r";
  }
  return "?";
}

UncertainRails UncertainRails::Apparatus(Uncertain L, Uncertain H, Uncertain D,
                                         LConvention convention) {
  UncertainRails r;
  r.given = Given::kApparatus;
  r.convention = convention;
  r.L = L;
  r.H = H;
  r.D = D;
  return r;
}

UncertainRails UncertainRails::Angles(Uncertain theta, Uncertain alpha) {
  UncertainRails r;
  r.given = Given::kAngles;
  r.theta = theta;
  r.alpha = alpha;
  return r;
}

UncertainBody UncertainBody::Sphere(Uncertain R) { return UncertainBody{BodyKind::kSphere, R, {}}; }
UncertainBody UncertainBody::Spheroid(Uncertain a, Uncertain b) {
  return UncertainBody{BodyKind::kSpheroid, a, b};
}
UncertainBody UncertainBody::DoubleCone(Uncertain R, Uncertain h) {
  return UncertainBody{BodyKind::kDoubleCone, R, h};
}

std::vector<const PropagatedValue*> PropagationResult::Outputs() const {
  std::vector<const PropagatedValue*> out = {&theta, &alpha, &phi};
  if (x_eq) out.push_back(&*x_eq);
  out.push_back(&x_max);
  if (theta0) out.push_back(&*theta0);
  return out;
}

PropagationResult Propagate(const UncertainRails& rails, const UncertainBody& body,
                            Uncertain rod_radius, const PropagationOptions& options) {
  ValidateOptions(options);
  const Problem p = MakeProblem(rails, body, rod_radius);

  PropagatedValue values[kOutCount];
  FirstOrder(p, values);

  PropagationResult result;
  result.trials = options.trials;
  if (options.trials == 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (PropagatedValue& v : values) v.mc_mean = v.u_monte_carlo = v.coverage_low = v.coverage_high = nan;
  } else {
    MonteCarloValue mc[kOutCount];
    MonteCarlo(p, options, &result, mc);
    for (int k = 0; k < kOutCount; ++k) {
      if (!HasOutput(p.body, k)) continue;
      const MonteCarloValue& mcv = mc[k];
      values[k].mc_mean = mcv.mean;
      values[k].u_monte_carlo = mcv.u;
      values[k].coverage_low = mcv.low;
      values[k].coverage_high = mcv.high;
      Flag(values[k], options.disagreement_tolerance);
      result.disagrees |= values[k].disagrees;
    }
  }
  result.theta = values[kOutTheta];
  result.alpha = values[kOutAlpha];
  result.phi = values[kOutPhi];
  result.x_max = values[kOutXMax];
  if (HasOutput(p.body, kOutXEq)) result.x_eq = values[kOutXEq];
  if (HasOutput(p.body, kOutTheta0)) result.theta0 = values[kOutTheta0];
  return result;
}


}  // namespace uphill
