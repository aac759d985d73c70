// What the benchmarks share: a one-core CPU clock, best-of-N timing with the peak resident memory
// of the timed work, finding the repository's files, running a peer (Python) script, and
// exchanging arrays with it.
//
// Peak memory. Every benchmark row states the peak resident set size (RSS) of the process that
// did the work, measured the same way on both sides: before the row, the allocator returns freed
// memory (malloc_trim) and the kernel's high-water mark VmHWM is reset to the current RSS (writing "5" to /proc/self/clear_refs, Linux ≥ 4.0); after
// it, VmHWM is read from /proc/self/status. The figure therefore includes the program itself and
// the row's input data as they were resident when the row started (as a user's process would
// hold them), plus whatever the work allocated and touched. The Python peers do the same
// (tools/bench/peak_memory.py); a program run end to end is measured by its own ru_maxrss
// (RunProcess). Where /proc/self/clear_refs cannot be written the peak is 0 ("n/a" in tables).
//
// Arrays cross to the peer as raw little-endian float64 files of shape (rows, n) in C order:
// NumPy reads them with np.fromfile(path, '<f8').reshape(rows, -1) and writes them with
// array.astype('<f8').tofile(path), so neither side needs a file-format library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace uphill::bench {

// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID): one core's work, not skewed by
// other load on the machine.
double CpuSeconds();
// CPU time of the whole process (CLOCK_PROCESS_CPUTIME_ID), for work that libraries spread over
// their own threads (FFmpeg's decoder): the work one core would have to do.
double ProcessCpuSeconds();
// Monotonic wall-clock time.
double WallSeconds();

// Returns freed heap memory to the system (malloc_trim) and resets the process's peak RSS to its
// current RSS; false where the kernel does not allow it.
bool ResetPeakResident();
// The process's peak RSS since the last reset (VmHWM), bytes; 0 if unknown.
std::uint64_t PeakResidentBytes();

// Time and peak memory of a measured piece of work.
struct Measurement {
  double seconds = 0.0;
  std::uint64_t peak_bytes = 0;
};

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

// BestOf, with the peak RSS over all repeats.
template <typename F>
Measurement Measure(int repeats, F&& f, double (*clock)() = CpuSeconds) {
  const bool reset = ResetPeakResident();
  Measurement m;
  m.seconds = BestOf(repeats, f, clock);
  m.peak_bytes = reset ? PeakResidentBytes() : 0;
  return m;
}

// A program run to its end in a child process (the benchmarks' end-to-end rows).
struct ProcessRun {
  int exit_status = -1;          // exit code, or -1 if it did not exit normally
  double wall_seconds = 0.0;     // from fork to the child's exit
  double cpu_seconds = 0.0;      // the child's user + system time
  std::uint64_t peak_bytes = 0;  // its ru_maxrss (which includes this process's anonymous
                                 // memory at the fork: keep it small before running children)
};
// Runs argv[0] with arguments (PATH searched), stdout to `stdout_path` ("" = /dev/null), stdin from
// /dev/null, stderr to `stderr_path` ("" = inherited). Throws std::runtime_error if it cannot start.
ProcessRun RunProcess(const std::vector<std::string>& argv, const std::string& stdout_path = "",
                      const std::string& stderr_path = "");

// A file of the repository (e.g. "tools/bench/numpy_convert.py"), found by walking up from the
// executable's directory and from the working directory, then in the installed PREFIX/share/uphill
// (relative to the installed program); "" if not found.
std::string FindUpward(const std::string& relative);
// The repository's root directory (the one holding tools/bench/), "" if not found.
std::string RepositoryRoot();

// s quoted for /bin/sh.
std::string ShellQuote(const std::string& s);

// Runs a shell command and collects its standard output; false if it could not run or failed.
bool Capture(const std::string& command, std::string* out);

// The prefix that keeps a Python peer on one core (NumPy's BLAS threads).
std::string OneCorePython(const std::string& python);

// Why a Python peer cannot run ("" if it can): `disabled_by` names the flag that turned it off
// (empty when on), `script` the peer's path ("" when not found: `script_hint` says where it
// should be), `module` a module the peer needs.
std::string PeerUnavailable(const std::string& disabled_by, const std::string& python,
                            const std::string& script, const std::string& script_hint,
                            const std::string& module);

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

// "12.3 us", "4.56 ms", "1.234 s".
std::string FormatSeconds(double seconds);
// "85 MB" (10^6 bytes, 3 significant digits); "n/a" for 0.
std::string FormatBytes(std::uint64_t bytes);
// "%.2g" of a relative deviation.
std::string FormatDeviation(double relative);
// "3.4x".
std::string FormatRatio(double ratio);
// "10^6" for powers of ten, else the number.
std::string FormatCount(std::uint64_t n);
// The largest |values[i] − reference[i]|/|reference[i]|.
double MaxRelativeDeviation(const std::vector<double>& values, const std::vector<double>& reference);

}  // namespace uphill::bench
