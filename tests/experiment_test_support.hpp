// Shared by the tests of experiment folders (experiment_test, experiment_v2_test).
#pragma once

#include <string>

#include "io/experiment.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {

// What LoadExperiment throws for the folder `dir` (InputError's message), or "loaded".
inline std::string LoadError(const std::string& dir) {
  try {
    LoadExperiment(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "loaded";
}

}  // namespace uphill::testing
