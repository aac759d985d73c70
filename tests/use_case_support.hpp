// Shared by the tests that call one use case of src/app through its three front ends (the
// program, the page's HTTP API, the Python module) on the same input: running a Python script
// against the built module. The test target defines UPHILL_PYTHON (the interpreter the module is
// built for) and UPHILL_PYTHON_MODULE_DIR.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_test_support.hpp"

namespace uphill::testing {

// Runs `script` (Python source) with the built module importable as `uphill`, from a file in
// `folder`; the result of the command.
inline CommandResult RunPython(const std::filesystem::path& folder, const std::string& script) {
  const std::filesystem::path file = folder / "use_case.py";
  std::ofstream(file) << script;
  return RunCommand(std::string("PYTHONPATH='") + UPHILL_PYTHON_MODULE_DIR + "' PYTHONDONTWRITEBYTECODE=1 '" +
                    UPHILL_PYTHON + "' '" + file.string() + "'");
}

// The JSON a script printed on its last line of stdout (the test fails when it did not run).
inline nlohmann::json PythonJson(const std::filesystem::path& folder, const std::string& script) {
  const CommandResult r = RunPython(folder, script);
  EXPECT_EQ(r.status, 0) << r.err;
  std::string last;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) last = line;
  return nlohmann::json::parse(last.empty() ? "null" : last);
}

// A fit's or an analysis' JSON without the solvers' wall-clock times (solver.seconds), the one
// entry that is not a result of the input.
inline nlohmann::json WithoutTimes(nlohmann::json j) {
  if (j.is_object()) {
    if (j.contains("solver") && j["solver"].is_object()) j["solver"].erase("seconds");
    for (auto& [key, value] : j.items()) value = WithoutTimes(value);
  } else if (j.is_array()) {
    for (auto& value : j) value = WithoutTimes(value);
  }
  return j;
}

}  // namespace uphill::testing
