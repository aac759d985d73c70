// Fuzz target: LoadExperiment (experiment.json + measurements.csv, data/README.md) and, when
// rows are usable, AnalyseExperiment without Monte Carlo (mc_trials = 0) and its JSON
// (what `uphill fit EXP --json` prints). Input: experiment.json, a NUL byte, measurements.csv
// (no NUL: measurements.csv is absent). The files go to a per-process temporary folder.
// Only uphill::InputError may escape; anything else (a crash, a sanitizer report, another
// exception) is a bug.
#include <pthread.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "io/experiment.hpp"
#include "model/input_error.hpp"
#include "report/analysis.hpp"
#include "report/fit_json.hpp"

namespace {

namespace fs = std::filesystem;
using namespace uphill;

const fs::path& Folder() {
  static const fs::path folder = [] {
    fs::path p = fs::temp_directory_path() / ("uphill_fuzz_experiment_" + std::to_string(getpid()));
    fs::create_directories(p);
    std::atexit([] { std::error_code ec; fs::remove_all(Folder(), ec); });
    return p;
  }();
  return folder;
}

void Write(const fs::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

// Loads (and analyses) the folder. Runs on a thread with a small stack (see below).
void* LoadAndAnalyse(void*) {
  try {
    const Experiment experiment = LoadExperiment(Folder().string());
    if (experiment.UsableRows().empty() || experiment.UsableRows().size() > 12) return nullptr;  // keeps runs fast
    AnalysisOptions options;
    options.mc_trials = 0;  // first-order u(X) only: Monte Carlo is the model's, not the reader's
    const ExperimentAnalysis analysis = AnalyseExperiment(experiment, options);
    (void)AnalysisToJson(analysis).dump();
  } catch (const InputError&) {
    // The documented refusal.
  }
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const size_t nul = input.find('\0');
  const fs::path& folder = Folder();
  Write(folder / "experiment.json", input.substr(0, nul));
  if (nul == std::string_view::npos) {
    std::error_code ec;
    fs::remove(folder / "measurements.csv", ec);
  } else {
    Write(folder / "measurements.csv", input.substr(nul + 1));
  }
  // A 256 KiB stack instead of the usual 8 MiB: recursion that grows with the input (JSON nesting)
  // then overflows within libFuzzer's 4 KiB inputs, as it would for a large file on a full stack.
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, 256 * 1024);
  pthread_t thread;
  if (pthread_create(&thread, &attr, LoadAndAnalyse, nullptr) != 0) std::abort();
  pthread_join(thread, nullptr);
  pthread_attr_destroy(&attr);
  return 0;
}
