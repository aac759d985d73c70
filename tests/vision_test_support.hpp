// Helpers shared by the vision tests.
#pragma once

#include <string>

#include "model/input_error.hpp"

namespace uphill::testing {

// The message of the InputError thrown by f, or "" if none was thrown.
template <class F>
std::string InputErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace uphill::testing
