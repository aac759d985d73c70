// The machine and the software a benchmark ran on, for the record in docs/benchmarks.md: the
// CPU model, its cores, the load average when the benchmark started, the date, the compiler and
// the libraries uphill was built with. A timing without these cannot be compared with another.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace uphill::bench {

struct Machine {
  std::string cpu;         // /proc/cpuinfo "model name", with its AVX2/FMA support
  int cores = 0;           // online logical CPUs
  double load[3] = {0, 0, 0};  // load average over 1, 5, 15 minutes, at the start
  std::string date;        // UTC, "2026-11-23 14:05 UTC"
  std::string kernel;      // uname -sr
};
Machine DescribeMachine();

// (name, version) of the compiler, the C library and the libraries compiled in.
std::vector<std::pair<std::string, std::string>> BuildVersions();

}  // namespace uphill::bench
