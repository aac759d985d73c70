#include "bench/support.hpp"

#include <fcntl.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <bit>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill::bench {

namespace fs = std::filesystem;
static_assert(std::endian::native == std::endian::little, "the float64 files are little-endian");

namespace {
double Clock(clockid_t id) {
  timespec ts;
  clock_gettime(id, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

double CpuSeconds() { return Clock(CLOCK_THREAD_CPUTIME_ID); }
double ProcessCpuSeconds() { return Clock(CLOCK_PROCESS_CPUTIME_ID); }
double WallSeconds() { return Clock(CLOCK_MONOTONIC); }

bool ResetPeakResident() {
  malloc_trim(0);  // return freed heap memory first, so that the baseline is what is live
  const int fd = open("/proc/self/clear_refs", O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = write(fd, "5", 1) == 1;
  close(fd);
  return ok;
}

std::uint64_t PeakResidentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;  // "  1234 kB"
  return 0;
}

ProcessRun RunProcess(const std::vector<std::string>& argv, const std::string& stdout_path,
                      const std::string& stderr_path) {
  if (argv.empty()) throw std::runtime_error("RunProcess: no program");
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const double start = WallSeconds();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot fork to run " + argv[0]);
  if (pid == 0) {
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(stdout_path.empty() ? "/dev/null" : stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0) _exit(127);
    dup2(in, 0);
    dup2(out, 1);
    if (!stderr_path.empty()) {
      const int err = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err < 0) _exit(127);
      dup2(err, 2);
    }
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) throw std::runtime_error("cannot wait for " + argv[0]);
  ProcessRun run;
  run.wall_seconds = WallSeconds() - start;
  run.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                    1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  run.peak_bytes = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // kB on Linux
  return run;
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
  // An installed program: the repository's files are installed under PREFIX/share/uphill with the
  // same relative paths, found relative to PREFIX/bin (so any prefix works, also a moved one).
  if (!exe.empty()) {
    const fs::path installed = exe.parent_path() / UPHILL_PKGDATADIR_FROM_BINDIR / relative;
    if (fs::exists(installed, ec)) return installed.lexically_normal().string();
  }
  return "";
}

std::string RepositoryRoot() {
  const std::string tools = FindUpward("tools/bench");
  return tools.empty() ? "" : fs::path(tools).parent_path().parent_path().string();
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

std::string PeerUnavailable(const std::string& disabled_by, const std::string& python,
                            const std::string& script, const std::string& script_hint,
                            const std::string& module) {
  if (!disabled_by.empty()) return disabled_by;
  if (access(python.c_str(), X_OK) != 0) return python + " not found";
  if (script.empty()) return script_hint;
  if (std::system((ShellQuote(python) + " -c 'import " + module + "' > /dev/null 2>&1").c_str()) != 0)
    return python + " has no " + module + " (bash scripts/install-deps.sh --bench)";
  return "";
}

TemporaryDirectory::TemporaryDirectory() {
  char name[] = "/tmp/uphill-bench-XXXXXX";
  if (!mkdtemp(name)) throw EnvironmentError("cannot create a temporary directory");
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
  if (!out) throw EnvironmentError("cannot write " + path.string());
}

std::vector<std::vector<double>> ReadFloat64(const fs::path& path, std::size_t rows, std::size_t n) {
  std::error_code ec;
  if (fs::file_size(path, ec) != rows * n * sizeof(double) || ec)
    throw std::runtime_error(path.string() + ": expected " + std::to_string(rows) + " x " + std::to_string(n) +
                             " float64 values");
  std::ifstream in(path, std::ios::binary);
  std::vector<std::vector<double>> out(rows, std::vector<double>(n));
  for (auto& row : out) in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(n * sizeof(double)));
  if (!in) throw EnvironmentError("cannot read " + path.string());
  return out;
}

namespace {
std::string Format(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}
}  // namespace

std::string FormatSeconds(double s) {
  if (!std::isfinite(s)) return "n/a";
  if (s < 1e-3) return Format("%.1f us", s * 1e6);
  if (s < 1.0) return Format("%.2f ms", s * 1e3);
  return Format("%.3f s", s);
}

std::string FormatBytes(std::uint64_t bytes) {
  if (bytes == 0) return "n/a";
  const double mb = static_cast<double>(bytes) / 1e6;
  return Format(mb < 10 ? "%.1f MB" : "%.0f MB", mb);
}

std::string FormatDeviation(double relative) { return Format("%.2g", relative); }

std::string FormatRatio(double ratio) { return Format(ratio < 10 ? "%.1fx" : "%.0fx", ratio); }

std::string FormatCount(std::uint64_t n) {
  const double e = std::log10(static_cast<double>(n));
  return std::abs(e - std::round(e)) < 1e-9 ? "10^" + std::to_string(static_cast<int>(std::round(e)))
                                             : std::to_string(n);
}

double MaxRelativeDeviation(const std::vector<double>& values, const std::vector<double>& reference) {
  double worst = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i)
    worst = std::max(worst, std::abs(values[i] - reference[i]) / std::abs(reference[i]));
  return worst;
}

}  // namespace uphill::bench
