#include "first_order.hpp"

#include <ceres/jet.h>

#include <cmath>

#include "model/double_cone_on_line_rails.hpp"
#include "model/spheroid_on_line_rails.hpp"
#include "spheroid_on_rods_closed_forms.hpp"

namespace uphill::internal {
namespace {

constexpr const char* kOutName[kOutCount] = {"theta", "alpha", "phi", "x_eq", "x_max", "theta0"};
constexpr const char* kOutUnit[kOutCount] = {"rad", "rad", "rad", "m", "m", "rad"};

// The model's templated closed forms, evaluated on jets.
template <typename S>
void ModelOutputs(const Problem& p, const S (&x)[kNumInputs], S (&y)[kOutCount]) {
  using std::atan2;
  using std::hypot;
  using std::tan;
  S B, T;
  if (p.given == UncertainRails::Given::kApparatus) {
    const S& L = x[Index(InputQuantity::kL)];
    const S& H = x[Index(InputQuantity::kH)];
    const S& D = x[Index(InputQuantity::kD)];
    // As Rails::FromApparatus: the measured ratios, θ and α by atan2.
    const S horizontal = HorizontalDistance(L, H, D, p.convention);
    B = H / horizontal;
    T = D / (2.0 * horizontal);
    y[kOutTheta] = atan2(H, horizontal);
    y[kOutAlpha] = 2.0 * atan2(D / 2.0, horizontal);
  } else {
    // As Rails::FromAngles.
    y[kOutTheta] = x[Index(InputQuantity::kTheta)];
    y[kOutAlpha] = x[Index(InputQuantity::kAlpha)];
    B = tan(y[kOutTheta]);
    T = tan(y[kOutAlpha] / 2.0);
  }
  y[kOutPhi] = atan2(T, hypot(S(1.0), B));  // as Rails::HalfAngleBetweenRails
  const S& across = x[Index(InputQuantity::kAcross)];
  const S& along = x[Index(InputQuantity::kAlong)];
  const S& r = x[Index(InputQuantity::kRodRadius)];
  // As Scene::MakePath.
  switch (p.body) {
    case BodyKind::kSphere: {
      const S R = p.rods ? S(across + r) : across;  // sphere on rods: radius R + r on the axes
      const SpheroidOnLineRails<S> path(R, R, B, T);
      y[kOutXEq] = path.x_eq();
      y[kOutXMax] = path.x_max();
      break;
    }
    case BodyKind::kSpheroid:
      if (p.rods) {
        y[kOutXEq] = SpheroidOnRodsXEq(across, along, B, T, r);
        y[kOutXMax] = SpheroidOnRodsXMax(across, along, T, r);
      } else {
        const SpheroidOnLineRails<S> path(across, along, B, T);
        y[kOutXEq] = path.x_eq();
        y[kOutXMax] = path.x_max();
      }
      break;
    case BodyKind::kDoubleCone: {
      const DoubleConeOnLineRails<S> cone(across, along, B, T);
      y[kOutXMax] = cone.x_fall();
      y[kOutTheta0] = cone.theta0();
      break;
    }
  }
}

}  // namespace

void FirstOrder(const Problem& p, PropagatedValue (&out)[kOutCount]) {
  using Jet = ceres::Jet<double, kNumInputs>;
  Jet x[kNumInputs];
  for (int i = 0; i < kNumInputs; ++i) x[i] = Jet(p.value[i], i);
  Jet y[kOutCount];
  ModelOutputs(p, x, y);
  // The values from the same template on doubles: Jet division computes f·(1/g), an ulp away from
  // f/g, and the reported value should be, to the bit, what the scalar model (Scene) gives.
  double value[kOutCount];
  ModelOutputs(p, p.value, value);
  for (int k = 0; k < kOutCount; ++k) {
    if (!HasOutput(p.body, k)) continue;
    PropagatedValue& v = out[k];
    v.name = kOutName[k];
    v.unit = kOutUnit[k];
    v.value = value[k];
    double sum = 0.0;
    for (int i = 0; i < kNumInputs; ++i) {
      if (!p.present[i]) continue;
      v.sensitivity[i] = y[k].v[i];
      // Exactly known inputs contribute exactly nothing (also when a derivative is not finite).
      if (p.u[i] > 0.0) sum += (y[k].v[i] * p.u[i]) * (y[k].v[i] * p.u[i]);
    }
    v.u_first_order = std::sqrt(sum);
  }
}

}  // namespace uphill::internal
