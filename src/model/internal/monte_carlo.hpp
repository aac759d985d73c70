// Internal to src/model: the Monte Carlo propagation of Propagate (GUM Supplement 1): Gaussian
// draws per input (GaussianStream), the outputs by the batch kernels, per output the mean, the
// standard deviation and the coverage interval (coverage_windows.hpp). See propagation.hpp for
// the contract, the reproducibility and the treatment of unphysical draws.
#pragma once

#include "propagation_problem.hpp"

namespace uphill::internal {

struct MonteCarloValue {
  double mean = 0, u = 0, low = 0, high = 0;
};

// Runs options.trials trials and fills values[k] for every output slot the body has, and in
// `result` the trial counts, rejected draws, samples (options.keep_samples) and window_reruns (a
// coverage window that missed its order statistic, improbable by design, reruns the same trials
// with exact selection from all of them).
void MonteCarlo(const Problem& p, const PropagationOptions& options, PropagationResult* result,
                MonteCarloValue (&values)[kOutCount]);

}  // namespace uphill::internal
