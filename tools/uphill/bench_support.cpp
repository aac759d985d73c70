#include "bench_support.hpp"

#include <time.h>
#include <unistd.h>

#include <bit>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace uphill::cli::bench {

namespace fs = std::filesystem;
static_assert(std::endian::native == std::endian::little, "the float64 files are little-endian");

double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string FindUpward(const std::string& relative) {
  std::vector<fs::path> starts;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) starts.push_back(exe.parent_path());
  starts.push_back(fs::current_path(ec));
  for (fs::path dir : starts) {
    for (int up = 0; up < 8 && !dir.empty(); ++up) {
      if (fs::exists(dir / relative, ec)) return (dir / relative).string();
      if (dir == dir.parent_path()) break;
      dir = dir.parent_path();
    }
  }
  return "";
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

bool Capture(const std::string& command, std::string* out) {
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return false;
  char buf[4096];
  std::size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, pipe)) > 0) out->append(buf, got);
  return pclose(pipe) == 0;
}

std::string OneCorePython(const std::string& python) {
  return "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 " + ShellQuote(python);
}

TemporaryDirectory::TemporaryDirectory() {
  char name[] = "/tmp/uphill-bench-XXXXXX";
  if (!mkdtemp(name)) throw std::runtime_error("cannot create a temporary directory");
  path_ = name;
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void WriteFloat64(const fs::path& path, const std::vector<const std::vector<double>*>& rows) {
  std::ofstream out(path, std::ios::binary);
  for (const auto* row : rows)
    out.write(reinterpret_cast<const char*>(row->data()), static_cast<std::streamsize>(row->size() * sizeof(double)));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::vector<std::vector<double>> ReadFloat64(const fs::path& path, std::size_t rows, std::size_t n) {
  std::error_code ec;
  if (fs::file_size(path, ec) != rows * n * sizeof(double) || ec)
    throw std::runtime_error(path.string() + ": expected " + std::to_string(rows) + " x " + std::to_string(n) +
                             " float64 values");
  std::ifstream in(path, std::ios::binary);
  std::vector<std::vector<double>> out(rows, std::vector<double>(n));
  for (auto& row : out) in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(n * sizeof(double)));
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return out;
}

}  // namespace uphill::cli::bench
