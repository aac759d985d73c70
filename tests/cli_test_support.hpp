// Runs the built `uphill` program (path from CMake) and captures stdout, stderr, exit status.
#pragma once

#include <string>

namespace uphill::testing {

struct CommandResult {
  int status = -1;
  std::string out, err;
};

// `args` is appended to the program path and run by /bin/sh; stdin from `input` if non-empty.
CommandResult RunUphill(const std::string& args, const std::string& input = "");

}  // namespace uphill::testing
