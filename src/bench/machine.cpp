#include "bench/machine.hpp"

#include <csv.h>
#include <gnu/libc-version.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <Eigen/Core>
#include <boost/version.hpp>
#include <ceres/version.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace uphill::bench {

Machine DescribeMachine() {
  Machine m;
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, flags;
  while (std::getline(cpuinfo, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, line.find_last_not_of(" \t", colon - 1) + 1);
    const std::string value = colon + 2 <= line.size() ? line.substr(colon + 2) : "";
    if (key == "model name" && m.cpu.empty()) m.cpu = value;
    if (key == "flags" && flags.empty()) flags = " " + value + " ";
  }
  if (m.cpu.empty()) m.cpu = "unknown CPU";
  // The vector extensions the benchmarks' kernels choose from at run time (vector_kernel.hpp: AVX2
  // with FMA; the Gaussian stream's Philox also AVX-512F), so that a row's speed can be read
  // against what the machine offered.
  auto has = [&](const char* flag) { return flags.find(std::string(" ") + flag + " ") != std::string::npos; };
  std::string simd;
  const std::pair<const char*, const char*> known[] = {{"avx2", "AVX2"}, {"fma", "FMA"}, {"avx512f", "AVX-512F"}};
  for (const auto& [flag, name] : known)
    if (has(flag)) simd += (simd.empty() ? "" : ", ") + std::string(name);
  if (!has("avx512f")) simd += simd.empty() ? "no AVX2, no AVX-512" : "; no AVX-512";
  m.cpu += " (" + simd + ")";
  m.cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  if (getloadavg(m.load, 3) != 3) m.load[0] = m.load[1] = m.load[2] = -1;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", &utc);
  m.date = date;
  utsname u{};
  if (uname(&u) == 0) m.kernel = std::string(u.sysname) + " " + u.release;
  return m;
}

std::vector<std::pair<std::string, std::string>> BuildVersions() {
  const auto str = [](auto... parts) {
    std::string s;
    ((s += (s.empty() ? "" : ".") + std::to_string(parts)), ...);
    return s;
  };
#if defined(__clang__)
  const std::string compiler = "clang++ " + std::string(__clang_version__);
#elif defined(__GNUC__)
  const std::string compiler = "g++ " + std::string(__VERSION__);
#else
  const std::string compiler = "unknown compiler";
#endif
  return {
      {"compiler", compiler},
      {"glibc", gnu_get_libc_version()},
      {"Ceres", CERES_VERSION_STRING},
      {"Eigen", str(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
      {"Boost", str(BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000, BOOST_VERSION % 100)},
      {"nlohmann-json", str(NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH)},
      {"libcsv", str(CSV_MAJOR, CSV_MINOR, CSV_RELEASE)},
  };
}

}  // namespace uphill::bench
