#include "cli_test_support.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace uphill::testing {

namespace {
std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

CommandResult RunCommand(const std::string& command_text, const std::string& input) {
  // A directory of its own per call: ctest runs test programs in parallel.
  std::string pattern = (std::filesystem::temp_directory_path() / "uphill_run_XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  const std::string dir = pattern;
  const std::string in_path = dir + "/stdin", out_path = dir + "/stdout", err_path = dir + "/stderr";
  std::ofstream(in_path) << input;
  const std::string command = command_text + " < " + in_path + " > " + out_path + " 2> " + err_path;
  const int raw = std::system(command.c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = Slurp(out_path);
  r.err = Slurp(err_path);
  std::filesystem::remove_all(dir);
  return r;
}

#ifdef UPHILL_PROGRAM
CommandResult RunUphill(const std::string& args, const std::string& input) {
  return RunCommand(std::string(UPHILL_PROGRAM) + " " + args, input);
}
#endif

}  // namespace uphill::testing
