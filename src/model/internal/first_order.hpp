// Internal to src/model: first-order (GUM) propagation of Propagate, by automatic
// differentiation (ceres::Jet) through the model's templated closed forms (propagation.hpp).
#pragma once

#include "propagation_problem.hpp"

namespace uphill::internal {

// Fills out[k] (name, unit, value, sensitivities, u_first_order) for every output slot the body
// has. `value` is the scalar model's to the bit (the closed forms evaluated on doubles).
void FirstOrder(const Problem& p, PropagatedValue (&out)[kOutCount]);

}  // namespace uphill::internal
