// What the benchmarks share: a one-core CPU clock, best-of-N timing, finding the repository's
// files, running a peer (Python) script, and exchanging arrays with it.
//
// Arrays cross to the peer as raw little-endian float64 files of shape (rows, n) in C order:
// NumPy reads them with np.fromfile(path, '<f8').reshape(rows, -1) and writes them with
// array.astype('<f8').tofile(path), so neither side needs a file-format library.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace uphill::cli::bench {

// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID): one core's work, not skewed by
// other load on the machine.
double CpuSeconds();
// CPU time of the whole process (CLOCK_PROCESS_CPUTIME_ID), for work that libraries spread over
// their own threads (FFmpeg's decoder): the work one core would have to do.
double ProcessCpuSeconds();

// The smallest time of `repeats` runs of f on `clock` (by default the thread's CPU time).
template <typename F>
double BestOf(int repeats, F&& f, double (*clock)() = CpuSeconds) {
  double best = INFINITY;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = clock();
    f();
    best = std::min(best, clock() - t0);
  }
  return best;
}

// A file of the repository (e.g. "tools/bench/numpy_convert.py"), found by walking up from the
// executable's directory and from the working directory; "" if not found.
std::string FindUpward(const std::string& relative);

// s quoted for /bin/sh.
std::string ShellQuote(const std::string& s);

// Runs a shell command and collects its standard output; false if it could not run or failed.
bool Capture(const std::string& command, std::string* out);

// The prefix that keeps a Python peer on one core (NumPy's BLAS threads).
std::string OneCorePython(const std::string& python);

// A temporary directory removed with everything in it when the object goes.
class TemporaryDirectory {
 public:
  TemporaryDirectory();
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Writes equal-length rows as a raw float64 (rows, n) file; throws std::runtime_error.
void WriteFloat64(const std::filesystem::path& path, const std::vector<const std::vector<double>*>& rows);
// Reads a raw float64 (rows, n) file; throws std::runtime_error if its size is not rows·n·8.
std::vector<std::vector<double>> ReadFloat64(const std::filesystem::path& path, std::size_t rows, std::size_t n);

}  // namespace uphill::cli::bench
