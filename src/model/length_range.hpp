// The range of the model's lengths (RequireModelLength) is one of the input ranges stated in
// model/input_ranges.hpp, the header every door includes.
#pragma once

#include "model/input_ranges.hpp"
