// Runs the built `uphill` program (path from CMake), or any command, and captures stdout, stderr,
// exit status.
#pragma once

#include <string>

namespace uphill::testing {

struct CommandResult {
  int status = -1;
  std::string out, err;
};

// `command` run by /bin/sh, stdin from `input` (empty: nothing).
CommandResult RunCommand(const std::string& command, const std::string& input = "");

// `args` is appended to the program path (UPHILL_PROGRAM) and run as RunCommand does.
CommandResult RunUphill(const std::string& args, const std::string& input = "");

}  // namespace uphill::testing
