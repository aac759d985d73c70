#include "bench/report_benchmark.hpp"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "app/video_trials.hpp"
#include "bench/results_document.hpp"
#include "bench/support.hpp"
#include "io/experiment.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "vision/camera.hpp"
#include "footage/synthetic_clip.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;

constexpr double kMu = 0.05;
constexpr const char* kExperimentVersion = "v1";  // bump when the rendered experiment changes

constexpr const char* kMethod =
    "An experiment folder of format uphill-experiment/2 whose N trials are videos rendered once with exact ground "
    "truth (src/footage/synthetic_clip.hpp, TrialClipSetup: a 2-inch ball on 8 mm rods, L = 1 m, H = 0.1 m, D from "
    "120 to 180 mm, rolling resistance mu = 0.05; H.264, noise sigma 1): half the trials are placed just inside the "
    "far edge of the rest band and stay (Y from the video), half are released beyond it after 8 s at rest and roll "
    "up and fall off (mu from the motion). \"report\": the `uphill report EXP -o OUT` program run as a user runs "
    "it, empty video cache, wall time from start to exit and its peak RSS (every video tracked and analysed, one "
    "per core, largest first, each trial's figures drawn as soon as it is tracked; then the fits, the other figures "
    "and the documents). \"tracking phase\": the report's first part alone, in the benchmark's process, from an "
    "empty cache: every video decoded, tracked, analysed and cached (TrackExperimentVideos, the call the program "
    "makes). \"decode only\": every frame of every video read by OpenCV (VideoCapture::read, FFmpeg, one decoding "
    "thread per video) on the same number of threads: the floor any tracker that reads every frame meets. The "
    "runs follow one another in rounds (--rounds, default 2: decode only, report, report cached, fit cached, "
    "tracking phase), and each row is its run's best round (shortest wall time), so that on a loaded machine "
    "the runs are compared at their least disturbed; the decodings of every round are stated. On a machine busier "
    "than its cores (load average above the thread count) wall times depend on how the kernel shares the cores "
    "among all the runnable threads, and the ratios of CPU time (\"Phases\") are the better guide. CPU: the process's over the run; of a program, its user + system time with its "
    "children's (gnuplot); CPU/frame divides it by the frames of all the videos, so that decoding and the "
    "tracker's share are seen apart. \"report, cached\": the same command again with nothing "
    "changed (the videos hashed, the cache read); \"fit, cached\": `uphill fit EXP` likewise (no figures). "
    "Accuracy: Y of the resting trials against the renderer's true position (largest |Y - truth| / u(Y)) and "
    "mu of the rolling trials (inverse-variance mean, its pull against 0.05).";

std::string Fixed(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

struct Trial {
  std::string name;
  double D = 0;
  bool rests = false;
  double true_x0 = 0;
};

std::vector<Trial> Trials(int n) {
  std::vector<Trial> out;
  for (int i = 0; i < n; ++i) {
    Trial t;
    t.D = 0.120 + 0.060 * (i / 2) / std::max(1, (n - 1) / 2);
    t.rests = i % 2 == 0;
    t.name = Fixed("t%02.0f", i + 1) + (t.rests ? "-rest" : "-roll");
    out.push_back(t);
  }
  return out;
}

// Renders the experiment (unless it is there, complete) and returns the seconds it took (0: reused).
double PrepareExperiment(const ReportBenchmarkOptions& o, const fs::path& exp, std::vector<Trial>* trials,
                         std::ostream& out) {
  const fs::path done = exp / ".rendered";
  for (Trial& t : *trials) {
    const ClipSetup s = TrialClipSetup(o.width, o.height, t.D, kMu, t.rests ? -0.02 : 0.3);
    t.true_x0 = s.x0;
  }
  if (!o.fresh && fs::exists(done)) return 0;
  fs::remove_all(exp);
  fs::create_directories(exp / "videos");
  out << "rendering " << trials->size() << " videos of " << o.width << "x" << o.height << ", " << o.seconds
      << " s into " << exp.string() << " (once) ..." << std::flush;
  const double start = WallSeconds();
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  const auto work = [&] {
    try {
      for (std::size_t i = next++; i < trials->size(); i = next++) {
        const Trial& t = (*trials)[i];
        const ClipSetup s = TrialClipSetup(o.width, o.height, t.D, kMu, t.rests ? -0.02 : 0.3);
        MotionOptions m;
        m.mu = kMu;
        m.method = MotionMethod::kOde;
        const Motion motion(s.scene, s.x0, m);
        ClipSettings c;
        c.fps = 30;
        c.frames = static_cast<int>(std::lround(o.seconds * c.fps));
        c.release_time = t.rests ? 0.0 : o.seconds - 2.0;
        c.noise_sigma = 1;
        c.seed = i + 1;
        const ClipRenderer renderer(s.scene, s.calibration, s.apparatus);
        RenderClip(renderer, motion, c, (exp / "videos" / (t.name + ".mp4")).string());
      }
    } catch (...) {
      failure = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  const unsigned jobs = o.jobs ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  for (unsigned j = 1; j < jobs; ++j) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
  const ClipSetup s = DefaultClipSetup(o.width, o.height);
  CalibrationSummary summary;
  summary.method = "synthetic camera (exact)";
  summary.verdict = "exact";
  WriteCameraFile((exp / "camera.json").string(), s.calibration.camera, summary);
  WriteSceneFile((exp / "scene.json").string(), s.calibration, summary);
  std::ofstream(exp / "experiment.json") << R"({"format": "uphill-experiment/2", "title": "uphill bench report",
  "body": {"type": "sphere", "R": "25.4 mm"}, "apparatus": {"L": "1000 mm", "H": "100 mm", "rod_diameter": "8 mm"},
  "uncertainties": {"L": "1 mm", "H": "0.5 mm", "D": "0.2 mm", "Y": "0.5 mm"},
  "camera": "camera.json", "scenes": {"main": "scene.json"}, "video_analysis": {"fit": "mu", "u_x": "0.3 mm"}})";
  std::ofstream csv(exp / "measurements.csv");
  csv << "trial,D_mm,Y_mm,video\n";
  for (const Trial& t : *trials)
    csv << t.name << "," << Fixed("%.1f", t.D * 1e3) << "," << (t.rests ? "" : Fixed("%.2f", t.true_x0 * 1e3))
        << ",videos/" << t.name << ".mp4\n";
  csv.close();
  std::ofstream(done) << "complete\n";
  const double seconds = WallSeconds() - start;
  out << " " << FormatSeconds(seconds) << "\n";
  return seconds;
}

// Wall time to read every frame of every video, `jobs` videos at once.
double DecodeAll(const std::vector<std::string>& videos, unsigned jobs, long* frames) {
  std::atomic<std::size_t> next{0};
  std::atomic<long> count{0};
  const auto work = [&] {
    for (std::size_t i = next++; i < videos.size(); i = next++) {
      cv::VideoCapture cap(videos[i], cv::CAP_FFMPEG);
      cv::Mat frame;
      long n = 0;
      while (cap.read(frame)) ++n;
      count += n;
    }
  };
  const double start = WallSeconds();
  std::vector<std::thread> threads;
  for (unsigned j = 1; j < jobs; ++j) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  *frames = count;
  return WallSeconds() - start;
}

}  // namespace

void RunReportBenchmark(const ReportBenchmarkOptions& o, std::ostream& out) {
  if (o.videos < 2 || o.videos > 200) throw InputError("--videos", "must be between 2 and 200");
  if (o.rounds < 1 || o.rounds > 20) throw InputError("--rounds", "must be between 1 and 20");
  if (o.seconds < 3 || o.seconds > 120) throw InputError("--seconds", "must be between 3 and 120 s");
  if (o.width < 320 || o.height < 180 || o.width > 4096 || o.height > 4096)
    throw InputError("--width/--height", "must be between 320x180 and 4096x4096");
  Section section = StartSection("report", o.common.command, kMethod);
  section.versions.emplace_back("OpenCV (C++)", CV_VERSION);
  OneDecodeThreadPerVideo();
  const unsigned jobs = o.jobs ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  const fs::path exp = fs::path(o.cache) / (std::string(kExperimentVersion) + "-" + std::to_string(o.videos) + "x" +
                                            std::to_string(o.height) + "p-" + Fixed("%.0fs", o.seconds));
  std::vector<Trial> trials = Trials(o.videos);
  const double render_seconds = PrepareExperiment(o, exp, &trials, out);
  if (render_seconds > 0)
    section.notes.push_back("Rendering the " + std::to_string(o.videos) + " videos (once, cached in " + exp.string() +
                            ") took " + FormatSeconds(render_seconds) + " of wall time on " + std::to_string(jobs) +
                            " threads.");

  std::vector<std::string> videos;
  for (const Trial& t : trials) videos.push_back((exp / "videos" / (t.name + ".mp4")).string());

  const std::string self = fs::read_symlink("/proc/self/exe").parent_path().string();
  const std::string uphill = (fs::path(self) / "uphill").string();
  const fs::path report_dir = exp.parent_path() / (exp.filename().string() + "-report");
  const std::string jobs_flag = std::to_string(jobs);
  const std::vector<std::string> report_argv = {uphill, "report", exp.string(), "-o", report_dir.string(),
                                                "--jobs", jobs_flag, "--quiet"};

  // Each round measures every run once, one after the other, from an empty cache and report
  // folder: decode only, report, report cached, fit cached, tracking phase. The best (shortest
  // wall time) of the rounds is kept for each, so that on a loaded machine the runs are compared
  // at their least disturbed. The in-process runs return their freed memory before a child is
  // started (a child's ru_maxrss counts this process's memory at the fork).
  long frames = 0;
  ProcessRun decode, first, second, fit, tracking;
  double tracker_own_cpu = 0;  // of the kept tracking round: the tracker's CPU alone, decoding excluded
  std::vector<double> decode_walls;
  std::vector<VideoTrial> results;
  const auto keep_best = [](ProcessRun* best, const ProcessRun& run) {
    if (best->exit_status != 0 || (run.exit_status == 0 && run.wall_seconds < best->wall_seconds)) *best = run;
  };
  for (int round = 0; round < o.rounds; ++round) {
    fs::remove_all(exp / ".uphill-cache");
    fs::remove_all(report_dir);
    ProcessRun d;
    const double decode_cpu0 = ProcessCpuSeconds();
    d.wall_seconds = DecodeAll(videos, jobs, &frames);
    d.cpu_seconds = ProcessCpuSeconds() - decode_cpu0;
    d.exit_status = 0;
    decode_walls.push_back(d.wall_seconds);
    keep_best(&decode, d);
    ResetPeakResident();
    keep_best(&first, RunProcess(report_argv));
    keep_best(&second, RunProcess(report_argv));
    keep_best(&fit, RunProcess({uphill, "fit", exp.string(), "--quiet"}));
    // The tracking phase alone, in this process: what `uphill report` does before its analysis,
    // figures and documents (app/video_trials.hpp, the same call), from an empty cache.
    fs::remove_all(exp / ".uphill-cache");
    Experiment experiment = LoadExperiment(exp.string());
    ProcessRun t;
    const double tracking_cpu0 = ProcessCpuSeconds(), tracking_wall0 = WallSeconds();
    results = TrackExperimentVideos(experiment, jobs);
    t.wall_seconds = WallSeconds() - tracking_wall0;
    t.cpu_seconds = ProcessCpuSeconds() - tracking_cpu0;
    t.exit_status = 0;
    if (tracking.exit_status != 0 || t.wall_seconds < tracking.wall_seconds) {
      tracker_own_cpu = 0;
      for (const VideoTrial& trial : results) tracker_own_cpu += trial.tracker_cpu_seconds;
    }
    keep_best(&tracking, t);
    ResetPeakResident();
  }
  if (first.exit_status != 0 || second.exit_status != 0 || fit.exit_status != 0)
    section.notes.push_back("exit status of report, report (cached), fit (cached): " +
                            std::to_string(first.exit_status) + ", " + std::to_string(second.exit_status) + ", " +
                            std::to_string(fit.exit_status) + " (expected 0)");
  const double decode_seconds = decode.wall_seconds, decode_cpu_seconds = decode.cpu_seconds;
  const double tracking_wall = tracking.wall_seconds, tracking_cpu = tracking.cpu_seconds;

  // Accuracy of the tracking phase's results (what the report shows).
  double worst_pull = 0;
  int rests = 0;
  for (std::size_t i = 0; i < results.size(); ++i)
    if (trials[i].rests && results[i].rest && results[i].rest->u) {
      worst_pull = std::max(worst_pull, std::abs(results[i].rest->value - trials[i].true_x0) / *results[i].rest->u);
      ++rests;
    }
  const std::optional<MotionMu> mu = WeightedMotionMu(results);

  out << "\nuphill bench report: " << o.videos << " trial videos, " << o.width << "x" << o.height << ", "
      << o.seconds << " s at 30 fps (" << frames << " frames), " << jobs << " threads; experiment in " << exp.string()
      << "\n\n";
  const auto per_frame = [&](double cpu) { return Fixed("%.2f ms", 1e3 * cpu / static_cast<double>(frames)); };
  Table table({{"run", 22, true}, {"wall", 9}, {"frames/s", 9}, {"x decode", 8}, {"CPU", 9}, {"CPU/frame", 10},
               {"peak RSS", 8}});
  table.Start(out);
  table.Add({"decode only", FormatSeconds(decode_seconds), Fixed("%.0f", frames / decode_seconds), "1.00",
             FormatSeconds(decode_cpu_seconds), per_frame(decode_cpu_seconds), ""});
  table.Add({"report", FormatSeconds(first.wall_seconds), Fixed("%.0f", frames / first.wall_seconds),
             Fixed("%.2f", first.wall_seconds / decode_seconds), FormatSeconds(first.cpu_seconds),
             per_frame(first.cpu_seconds), FormatBytes(first.peak_bytes)});
  table.Add({"tracking phase", FormatSeconds(tracking_wall), Fixed("%.0f", frames / tracking_wall),
             Fixed("%.2f", tracking_wall / decode_seconds), FormatSeconds(tracking_cpu), per_frame(tracking_cpu), ""});
  table.Add({"report, cached", FormatSeconds(second.wall_seconds), "", Fixed("%.2f", second.wall_seconds / decode_seconds),
             FormatSeconds(second.cpu_seconds), "", FormatBytes(second.peak_bytes)});
  table.Add({"fit, cached", FormatSeconds(fit.wall_seconds), "", Fixed("%.2f", fit.wall_seconds / decode_seconds),
             FormatSeconds(fit.cpu_seconds), "", FormatBytes(fit.peak_bytes)});
  section.tables.emplace_back("", &table);

  std::string decodes = "Decode only, wall time of each round:";
  for (std::size_t r = 0; r < decode_walls.size(); ++r) decodes += (r ? ", " : " ") + FormatSeconds(decode_walls[r]);
  decodes += " (the rounds' spread is the load's doing).";
  out << "\n" << decodes << "\n";
  section.results.push_back(decodes);
  const std::string phases =
      "Phases: per frame, decoding costs " + per_frame(decode_cpu_seconds) + " of CPU (the decode-only run) and the "
      "tracking phase " + per_frame(tracking_cpu) + ", of which the tracker itself " + per_frame(tracker_own_cpu) +
      " (its thread's CPU around each frame's tracking, decoding excluded; the rest is decoding, hashing, the "
      "analysis and the cache). With every core busy the tracking phase can come no closer to decode-only than " +
      Fixed("%.2f", tracking_cpu / decode_cpu_seconds) + "x (" +
      Fixed("%.2f", (decode_cpu_seconds + tracker_own_cpu) / decode_cpu_seconds) +
      "x from the tracker's own CPU alone), and the report " + Fixed("%.2f", first.cpu_seconds / decode_cpu_seconds) +
      "x (its CPU beyond the tracking phase: " + FormatSeconds(first.cpu_seconds - tracking_cpu) +
      " for the analysis, the figures' gnuplot processes, the documents and the program's start).";
  out << phases << "\n";
  section.results.push_back(phases);
  std::string accuracy = "Accuracy: Y of " + std::to_string(rests) + " resting trials within " +
                         Fixed("%.2f", worst_pull) + " u(Y) of the truth (largest)";
  if (mu)
    accuracy += "; mu of " + std::to_string(mu->trials) + " rolling trials " + Fixed("%.5f", mu->mu) + " ± " +
                Fixed("%.5f", mu->u) + " (truth 0.05, pull " + Fixed("%.2f", (mu->mu - kMu) / mu->u) + ")";
  out << accuracy << ".\n";
  section.results.push_back(accuracy + ".");
  const double report_ratio = first.wall_seconds / decode_seconds, tracking_ratio = tracking_wall / decode_seconds;
  const auto within = [](double ratio) { return ratio <= 1.10 ? std::string("met") : std::string("not met"); };
  // The issue's speed goal is the tracking: each video at its decode-limited speed. The report as a
  // whole adds its figures (two gnuplot renderings per figure), fits and documents; its wall time
  // against decode-only is reported beside it.
  const std::string goal =
      "Goal (issue 13): each video tracked at its decode-limited speed, every core used across videos (met when "
      "the tracking phase's wall time is within 10 % of decode-only): " + Fixed("%.2f", tracking_ratio) + "x (" +
      within(tracking_ratio) + "); the whole report, its figures and documents included, " +
      Fixed("%.2f", report_ratio) + "x decode (reported; within 10 %: " + within(report_ratio) +
      "); a second report of the unchanged folder < 1 s: " + FormatSeconds(second.wall_seconds) +
      " for the report with its figures (" + (second.wall_seconds < 1 ? "met" : "not met") + "), " +
      FormatSeconds(fit.wall_seconds) + " for `uphill fit` (" + (fit.wall_seconds < 1 ? "met" : "not met") + ").";
  out << goal << "\n";
  section.results.push_back(goal);
  Record(section, o.common.doc, o.common.no_doc, out);
}

}  // namespace uphill::bench
