#include "vision_program.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "model/input_error.hpp"

namespace uphill::cli {
namespace {

std::vector<char*>& Arguments() {
  static std::vector<char*> arguments;
  return arguments;
}

}  // namespace

void RememberArguments(int argc, char** argv) { Arguments().assign(argv, argv + argc); }

void RunInVisionProgram() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path sibling = self.parent_path() / "uphill-vision";
  if (ec || !fs::exists(sibling, ec))
    throw InputError(sibling.string(), "is missing: the video commands (track, calibrate, analyse-track, fit/report of "
                                       "an experiment, serve, bench track/report) run in it, installed next to uphill");
  std::vector<char*> argv = Arguments();
  const std::string path = sibling.string();
  if (argv.empty()) argv.push_back(const_cast<char*>(path.c_str()));
  argv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  execv(path.c_str(), argv.data());
  throw InputError(path, std::string("cannot be run: ") + std::strerror(errno));
}

}  // namespace uphill::cli
