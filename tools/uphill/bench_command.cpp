// `uphill bench <what>`: the benchmarks of src/bench (speed against accuracy and memory, with
// their peers, recorded in docs/benchmarks.md). This file only maps flags to their options.
#include <iostream>
#include <memory>

#include "bench/convert_benchmark.hpp"
#include "bench/fit_benchmark.hpp"
#include "bench/io_benchmark.hpp"
#include "bench/motion_benchmark.hpp"
#include "bench/python_benchmark.hpp"
#include "bench/report_benchmark.hpp"
#include "bench/track_benchmark.hpp"
#include "commands.hpp"
#include "vision_program.hpp"

namespace uphill::cli {
namespace {

// The flags every benchmark has, and the command line for the record.
void AddCommonFlags(CLI::App* cmd, bench::CommonOptions* common, const std::string& python_help) {
  cmd->add_option("--python", common->python, python_help)->capture_default_str();
  cmd->add_option("--doc", common->doc, "file to record the results in (default: the repository's docs/benchmarks.md)");
  cmd->add_flag("--no-doc", common->no_doc, "do not record the results in docs/benchmarks.md");
}

std::string CommandLine(const std::vector<std::string>& arguments) {
  std::string line = "uphill";
  for (const std::string& a : arguments) line += " " + a;
  return line;
}

// When `cmd` is chosen: `run` with the options, the command line recorded with the results.
template <class Options>
void RunsWith(CLI::App* cmd, const std::shared_ptr<Options>& o, const std::shared_ptr<std::vector<std::string>>& argv,
              void (*run)(const Options&, std::ostream&)) {
  cmd->callback([o, argv, run] {
    o->common.command = CommandLine(*argv);
    run(*o, std::cout);
  });
}

#if UPHILL_VISION_PROGRAM
using bench::RunReportBenchmark;
using bench::RunTrackBenchmark;
#else  // uphill: the video benchmarks run in uphill-vision (vision_program.hpp)
void RunTrackBenchmark(const bench::TrackBenchmarkOptions&, std::ostream&) { RunInVisionProgram(); }
void RunReportBenchmark(const bench::ReportBenchmarkOptions&, std::ostream&) { RunInVisionProgram(); }
#endif

void AddFit(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::FitBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "fit", "Line and friction fits: time, accuracy and memory against extended precision and NumPy/SciPy");
  cmd->add_option("--sizes", o->sizes, "rows of the straight-line cases")->delimiter(',')->capture_default_str();
  cmd->add_option("--friction-sizes", o->friction_sizes, "rows of the friction-model cases")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--offset-rows", o->offset_rows, "rows of the X = 1e9 case (0: skip)")->capture_default_str();
  cmd->add_option("--seed", o->seed, "seed of the synthetic data")->capture_default_str();
  cmd->add_option("--repeats", o->repeats, "timed repeats per fit (the best counts)")->capture_default_str();
  AddCommonFlags(cmd, &o->common, "Python with NumPy/SciPy for the peers");
  cmd->add_option("--peer-script", o->script, "path of tools/bench/fit_peers.py");
  cmd->add_flag("--no-peers", o->no_peers, "skip the NumPy/SciPy peers");
  cmd->add_flag("--no-odr", o->no_odr, "skip scipy.odr (slow at 10^6 rows)");
  cmd->add_flag("--no-rlm", o->no_rlm, "skip statsmodels' RLM (slow at 10^6 rows)");
  RunsWith(cmd, o, argv, bench::RunFitBenchmark);
}

void AddIo(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::IoBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "io", "fit --xy and convert --batch end to end on large files, against NumPy; bad input at scale");
  cmd->add_option("--sizes", o->sizes, "rows of the files")->delimiter(',')->capture_default_str();
  cmd->add_option("--seed", o->seed, "seed of the synthetic files")->capture_default_str();
  cmd->add_option("--repeats", o->repeats, "runs per workload at up to 10^6 rows (the best counts)")
      ->capture_default_str();
  cmd->add_option("--folder", o->folder, "folder for the files (default: a temporary one, removed after)");
  AddCommonFlags(cmd, &o->common, "Python with NumPy for the peer");
  cmd->add_option("--peer-script", o->script, "path of tools/bench/io_peers.py");
  cmd->add_flag("--no-peers", o->no_peers, "skip the NumPy peer");
  cmd->add_flag("--no-bad-input", o->no_bad_input, "skip the bad-input cases");
  cmd->add_option("--long-line-bytes", o->long_line_bytes, "length of the line without a line end")
      ->capture_default_str();
  RunsWith(cmd, o, argv, bench::RunIoBenchmark);
}

void AddConvert(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::ConvertBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "convert", "Conversion and Monte Carlo throughput per core, with accuracy and memory, against NumPy");
  cmd->add_option("--configurations", o->configurations, "random configurations to convert")->capture_default_str();
  cmd->add_option("--trials", o->trials, "Monte Carlo trials")->capture_default_str();
  cmd->add_option("--seed", o->seed, "seed of the configurations and of the Monte Carlo")->capture_default_str();
  cmd->add_option("--repeats", o->repeats, "timed repeats per row (the best counts)")->capture_default_str();
  AddCommonFlags(cmd, &o->common, "Python with NumPy for the comparison");
  cmd->add_option("--numpy-script", o->script, "path of tools/bench/numpy_convert.py");
  cmd->add_option("--reference", o->reference, "path of tests/data/physics_reference.json");
  cmd->add_flag("--no-numpy", o->no_numpy, "skip the NumPy comparison");
  RunsWith(cmd, o, argv, bench::RunConvertBenchmark);
}

void AddMotion(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::MotionBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand("motion", "Work-precision of the motion methods, against SciPy/NumPy");
  cmd->add_option("-o,--out", o->out, "folder for the work-precision figure")->capture_default_str();
  AddCommonFlags(cmd, &o->common, "Python with SciPy for the comparison");
  cmd->add_option("--script", o->script, "path of tools/bench/motion_peers.py");
  cmd->add_flag("--no-python", o->no_python, "skip the SciPy/NumPy comparison");
  cmd->add_flag("--release-only", o->release_only, "only the ReleaseTimes rows (no Motion rows, no peers)");
  RunsWith(cmd, o, argv, bench::RunMotionBenchmark);
}

void AddTrack(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::TrackBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand("track", "Ball tracking: fps against decoding, RMS error, OpenCV peers");
  cmd->add_option("--cache", o->cache, "folder of the rendered clips (reused between runs)")->capture_default_str();
  cmd->add_flag("--fresh", o->fresh, "render the clips again");
  AddCommonFlags(cmd, &o->common, "Python with cv2 for the peers");
  cmd->add_option("--script", o->script, "path of tools/bench/track_peers.py");
  cmd->add_flag("--no-python", o->no_python, "skip the OpenCV peers");
  cmd->add_flag("--no-matrix", o->no_matrix, "skip the robustness table on the ray-traced footage");
  cmd->add_flag("--only-matrix", o->only_matrix, "only the robustness table");
  cmd->add_option("--conditions", o->conditions, "robustness conditions to run (default: all)")->delimiter(',');
  cmd->add_option("--footage-cache", o->footage_cache, "ray-traced clips (default ~/.cache/uphill/clips)");
  cmd->add_option("--positions", o->positions,
                  "folder to write each ray-traced clip's frames in, tracked against the truth (<condition>.csv)");
  CLI::Option* random =
      cmd->add_option("--random", o->random,
                      "only N freshly drawn ray-traced scenes, the tracker beside the baseline (docs/bench.md)")
          ->check(CLI::Range(1, 100000));
  cmd->add_option("--seed", o->seed, "seed of the random scenes (default: a new one, printed)")->needs(random);
  cmd->add_option("--random-cache", o->random_cache, "folder of the random scenes' clips (<seed>/ inside)")
      ->capture_default_str()
      ->needs(random);
  cmd->add_option("--json", o->json, "file for the random scenes' results (JSON)")->needs(random);
  cmd->add_option("--draw", o->draw_ids, "only the draws with these ids (to replay one; with --seed)")
      ->delimiter(',')
      ->needs(random);
  cmd->add_option("--min-quality", o->min_quality,
                  "the tracker's --min-quality (uphill track), to compare its rule on the same draws")
      ->needs(random);
  RunsWith(cmd, o, argv, RunTrackBenchmark);
}

void AddReport(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::ReportBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "report", "Fit report of an experiment of trial videos: wall time against decoding them, the cached rerun");
  cmd->add_option("--cache", o->cache, "folder of the rendered experiment (reused between runs)")->capture_default_str();
  cmd->add_flag("--fresh", o->fresh, "render the videos again");
  cmd->add_option("--videos", o->videos, "number of trial videos")->capture_default_str();
  cmd->add_option("--width", o->width, "video width, px")->capture_default_str();
  cmd->add_option("--height", o->height, "video height, px")->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "length of each video, s (>= 3)")->capture_default_str();
  cmd->add_option("--jobs", o->jobs, "threads (0: every core)")->capture_default_str();
  cmd->add_option("--rounds", o->rounds, "rounds of all the runs; each run's best is kept")->capture_default_str();
  AddCommonFlags(cmd, &o->common, "unused (no Python peer: decoding is the baseline)");
  RunsWith(cmd, o, argv, RunReportBenchmark);
}

void AddPython(CLI::App& bench, const std::shared_ptr<std::vector<std::string>>& argv) {
  auto o = std::make_shared<bench::PythonBenchmarkOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "python", "The Python module's calls against the C++ kernels and NumPy, in one Python process");
  cmd->add_option("--elements", o->elements, "elements (and York rows) per call")->capture_default_str();
  cmd->add_option("--seed", o->seed, "seed of the synthetic data")->capture_default_str();
  cmd->add_option("--repeats", o->repeats, "timed repeats per row (the best counts)")->capture_default_str();
  AddCommonFlags(cmd, &o->common, "Python with NumPy that imports the module");
  cmd->add_option("--script", o->script, "path of tools/bench/python_module.py");
  cmd->add_option("--module-dir", o->module_dir, "folder of the module to import (default: this build's)");
  RunsWith(cmd, o, argv, bench::RunPythonBenchmark);
}

}  // namespace

void AddBenchCommand(CLI::App& app, const std::vector<std::string>& arguments) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: speed against error and memory, with peers");
  bench->require_subcommand(1);
  const auto argv = std::make_shared<std::vector<std::string>>(arguments);
  AddConvert(*bench, argv);
  AddFit(*bench, argv);
  AddIo(*bench, argv);
  AddMotion(*bench, argv);
  AddTrack(*bench, argv);
  AddReport(*bench, argv);
  AddPython(*bench, argv);
}

}  // namespace uphill::cli
