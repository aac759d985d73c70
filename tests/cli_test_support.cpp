#include "cli_test_support.hpp"

#include <sys/wait.h>

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

std::string TempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("uphill_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

CommandResult RunUphill(const std::string& args, const std::string& input) {
  const std::string dir = TempDir("run");
  const std::string in_path = dir + "/stdin", out_path = dir + "/stdout", err_path = dir + "/stderr";
  std::ofstream(in_path) << input;
  const std::string command = std::string(UPHILL_PROGRAM) + " " + args + " < " + in_path + " > " +
                              out_path + " 2> " + err_path;
  const int raw = std::system(command.c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = Slurp(out_path);
  r.err = Slurp(err_path);
  return r;
}

}  // namespace uphill::testing
