// Internal to src/model: the scene of a Propagate call in the form both propagation methods
// (first_order.hpp, monte_carlo.hpp) read: which inputs exist, their values and standard
// uncertainties, and which outputs the body has.
#pragma once

#include "model/propagation.hpp"

namespace uphill::internal {

constexpr int kNumInputs = kInputQuantityCount;
constexpr int Index(InputQuantity q) { return static_cast<int>(q); }

struct Problem {
  UncertainRails::Given given;
  LConvention convention;
  BodyKind body;
  bool rods;  // rod radius > 0
  bool present[kNumInputs] = {};
  double value[kNumInputs] = {};
  double u[kNumInputs] = {};
};

// The Problem of Propagate's arguments. Throws InputError for a bad uncertainty, and the model's
// own InputError (with its message) for a value out of range or a scene not modelled.
Problem MakeProblem(const UncertainRails& rails, const UncertainBody& body, Uncertain rod);

// Throws InputError naming trials, coverage or disagreement tolerance.
void ValidateOptions(const PropagationOptions& o);

// Output slots, in Outputs() order; which exist depends on the body.
enum OutputSlot { kOutTheta, kOutAlpha, kOutPhi, kOutXEq, kOutXMax, kOutTheta0, kOutCount };
bool HasOutput(BodyKind body, int slot);

}  // namespace uphill::internal
