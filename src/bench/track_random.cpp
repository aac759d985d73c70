#include "bench/track_random.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>
#include <random>

#include "bench/baseline_edge_tracker.hpp"
#include "bench/results_document.hpp"
#include "bench/track_random_analysis.hpp"
#include "bench/track_random_draw.hpp"
#include "footage/footage_clip.hpp"
#include "io/atomic_file.hpp"
#include "io/json_file.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/video_tracking.hpp"

namespace uphill::bench {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

std::string Fixed(const char* format, double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

TrackerOptions OptionsFor(const DecodedClip& clip) {
  TrackerOptions o;
  o.fps = clip.fps;
  o.measure_readout = clip.rolling_shutter;
  return o;
}

// The sidecar's "models" (an object of name → choice, or a list), joined; "-" without one.
std::string ModelsOfSidecar(const std::string& path) {
  if (!fs::exists(path)) return "-";
  const nlohmann::json side = ReadJsonFile(path);
  const auto it = side.find("models");
  if (it == side.end() || it->empty()) return "-";
  std::string out;
  if (it->is_object())
    for (const auto& [name, value] : it->items())
      out += (out.empty() ? "" : " ") + name + "=" + (value.is_string() ? value.get<std::string>() : value.dump());
  else
    for (const auto& value : *it) out += (out.empty() ? "" : " ") + (value.is_string() ? value.get<std::string>() : value.dump());
  return out;
}

// The radius, in standard deviations per axis, of the circle that holds 95 % of a 2-D normal
// error: sqrt(−2·ln 0.05).
constexpr double kCoverage95 = 2.4477;

// One tracker's score on one draw.
struct Score {
  int in_view = 0;       // frames with the body at least half visible
  int found = 0;         // of those, with a position
  int silent_wrong = 0;  // positions > 1 px from the truth, or where no body is in view
  // Of the frames found in view with a stated uncertainty u, those within 2.45 u of the truth
  // (the 95 % circle of an error of standard deviation u on each image axis).
  int stated = 0, within_stated = 0;
  double px_rms = NAN, px_p95 = NAN, mm_rms = NAN;
  std::string models = "-", refusal;
};

Score ScoreOf(const TrackerOutput& out, const std::vector<ClipTruth>& truth, const Motion& motion,
              double release_time) {
  Score s;
  s.models = out.models;
  s.refusal = out.refusal;
  std::vector<double> px;
  double mm2 = 0;
  int mm_n = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const ClipTruth& t = truth[i];
    const bool in_view = t.present && t.visibility >= 0.5;
    s.in_view += in_view;
    if (i >= out.frames.size() || !out.frames[i].found) continue;
    const TrackedFrame& f = out.frames[i];
    const bool body = t.present && t.visibility > 0;
    const double error = body ? std::hypot(f.u - t.u, f.v - t.v) : INFINITY;
    s.silent_wrong += error > 1;
    if (!in_view) continue;
    ++s.found;
    px.push_back(error);
    if (std::isfinite(f.uncertainty_px)) ++s.stated, s.within_stated += error <= kCoverage95 * f.uncertainty_px;
    const double tm = std::max(0.0, f.t - release_time);
    if (tm <= motion.end_time()) {
      const double dx = (f.x - motion.At(tm).x) * 1e3;
      mm2 += dx * dx;
      ++mm_n;
    }
  }
  if (!px.empty()) {
    double sum = 0;
    for (double e : px) sum += e * e;
    s.px_rms = std::sqrt(sum / px.size());
    std::sort(px.begin(), px.end());
    s.px_p95 = px[std::min(px.size() - 1, static_cast<size_t>(std::ceil(0.95 * px.size())) - 1)];
  }
  if (mm_n > 0) s.mm_rms = std::sqrt(mm2 / mm_n);
  return s;
}

// The p-quantile (nearest rank) of the finite values; NaN if none.
double Quantile(std::vector<double> values, double p) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
               values.end());
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(std::ceil(p * values.size()));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

ordered_json AnalysisJson(const AnalysisScore& a) {
  ordered_json pulls = ordered_json::array();
  for (const AnalysisPull& p : a.pulls)
    pulls.push_back({{"name", p.name},
                     {"error", p.error},
                     {"u", p.u},
                     {"u_statistical", p.u_statistical},
                     {"u_systematic", p.u_systematic}});
  return {{"kind", a.kind}, {"pulls", pulls}};
}

ordered_json ScoreJson(const Score& s) {
  const auto number = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(); };
  return {{"px_rms", number(s.px_rms)},   {"px_p95", number(s.px_p95)},         {"mm_rms_x", number(s.mm_rms)},
          {"frames_in_view", s.in_view},  {"frames_found", s.found},            {"silent_wrong", s.silent_wrong},
          {"frames_with_u", s.stated},    {"within_95_of_u", s.within_stated},  {"models", s.models},
          {"refusal", s.refusal}};
}

std::vector<cv::Mat> Decode(const std::string& video) {
  cv::VideoCapture capture(video, cv::CAP_FFMPEG);
  std::vector<cv::Mat> frames;
  for (cv::Mat frame; capture.read(frame);) frames.push_back(frame.clone());
  return frames;
}

struct Draw {
  RandomScene scene;
  FootageFiles files;
  Score core, baseline;
  AnalysisScore analysis;  // of the core's track
};

// A pull's value in the unit the lab reads: mm, ms, m/s², or μ as is.
std::string PullText(const AnalysisPull& p) {
  const double scale = p.name == "Y" || p.name == "x0" ? 1e3 : p.name == "t0" ? 1e3 : 1;
  const char* unit = p.name == "Y" || p.name == "x0" ? " mm" : p.name == "t0" ? " ms" : p.name == "g" ? " m/s2" : "";
  return p.name + Fixed(" %+.4g", p.error * scale) + unit + Fixed(" ± %.2g", p.u * scale) + Fixed(" (pull %+.2f)", p.Pull());
}

std::string AnalysisText(const AnalysisScore& a) {
  std::string text = "  analyse-track: " + a.kind;
  for (size_t i = 0; i < a.pulls.size(); ++i) text += (i ? ", " : ": ") + PullText(a.pulls[i]);
  return text + "\n";
}

std::vector<std::string> Cells(const std::string& tracker, const Score& s) {
  return {tracker,
          Fixed("%.3f", s.px_rms),
          Fixed("%.3f", s.px_p95),
          Fixed("%.3f", s.mm_rms),
          std::to_string(s.in_view),
          std::to_string(s.found),
          std::to_string(s.silent_wrong),
          s.refusal.empty() ? s.models : "refused: " + s.refusal};
}

}  // namespace

TrackerOutput TrackWithCore(const DecodedClip& clip, double min_report_quality) {
  TrackerOutput out;
  TrackVideoOptions options;
  options.tracker = OptionsFor(clip);
  options.tracker.min_report_quality = min_report_quality;
  TrackResult result;
  try {
    result = TrackVideo(clip.video, clip.scene, clip.calibration, options);
  } catch (const InputError& e) {
    out.refusal = e.what();
    return out;
  }
  const std::string csv = (fs::path(clip.work_dir) / "core.csv").string();
  WriteTrack(csv, result, {clip.video, "", "", ""});
  out.models = ModelsOfSidecar(csv + ".json");
  for (const TrackRow& row : result.rows)
    out.frames.push_back({row.ball.found, row.ball.u, row.ball.v, row.ball.found ? row.u_px : NAN, row.ball.x, row.t});
  return out;
}

TrackerOutput TrackWithBaseline(const DecodedClip& clip) {
  TrackerOutput out;
  try {
    BaselineEdgeTracker tracker(clip.scene, clip.calibration);
    for (size_t k = 0; k < clip.frames.size(); ++k) {
      const BaselineObservation b = tracker.Track(clip.frames[k]);
      out.frames.push_back({b.found, b.u, b.v, NAN, b.x, k / clip.fps});
    }
  } catch (const InputError& e) {
    out.frames.clear();
    out.refusal = e.what();
  }
  return out;
}

void RunTrackRandom(const TrackRandomOptions& o, std::ostream& out) {
  if (o.draws < 1) throw InputError("--random", "must be at least 1 draw");
  const std::uint64_t seed =
      o.seed ? *o.seed : (static_cast<std::uint64_t>(std::random_device{}()) << 32) ^ std::random_device{}();
  const fs::path root = fs::path(o.cache) / std::to_string(seed);
  fs::create_directories(root);
  out << "\nrandom scenes: " << o.draws << " draws, seed " << seed << " (again: uphill bench track --random "
      << o.draws << " --seed " << seed << "); clips in " << root.string() << "\n"
      << "truth: the renderer's projected centre, and x(t) of uphill::Motion (src/motion), independent of the "
         "trackers; tracked with the true camera\n\n"
      << std::flush;
  Table table({{"draw", 8, true}, {"tracker", 8, true}, {"px RMS", 7}, {"px p95", 7}, {"mm RMS x", 8},
               {"in view", 7}, {"found", 5}, {"silent wrong", 12}, {"models", 24, true}});
  std::vector<Draw> draws;
  ordered_json json_draws = ordered_json::array();
  const bool tty = isatty(STDERR_FILENO);
  for (int k = 0; k < o.draws; ++k) {
    Draw d;
    d.scene = DrawRandomScene(DrawSeed(seed, k));
    if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), d.scene.id) == o.only.end()) continue;
    const FootageCondition& c = d.scene.condition;
    out << "draw " << d.scene.id << ": " << d.scene.Summary() << "\n" << std::flush;
    FootageProgress progress;
    progress.report = [&](const std::string& stage, int done, int total) {
      if (tty) std::fprintf(stderr, "\r  rendering %s: %s %d/%d   ", d.scene.id.c_str(), stage.c_str(), done + 1, total);
    };
    d.files = RenderFootage(c, root.string(), o.fresh, progress);
    if (tty) std::fprintf(stderr, "\r%80s\r", "");
    const std::vector<ClipTruth> truth = ReadFootageTruth(d.files.truth_csv);
    const Motion motion(c.scene, c.x0, c.motion);
    const fs::path work = root / "tracks" / d.scene.id;
    fs::create_directories(work);
    DecodedClip clip{d.files.video, Decode(d.files.video), c.scene, c.camera, c.shutter.fps,
                     c.shutter.readout > 0, work.string()};
    d.core = ScoreOf(o.core(clip), truth, motion, c.release_time);
    d.baseline = ScoreOf(o.baseline(clip), truth, motion, c.release_time);
    d.analysis = ScoreAnalysis((work / "core.csv").string(), c);
    if (draws.empty()) table.Start(out);
    std::vector<std::string> row = Cells("core", d.core);
    row.insert(row.begin(), d.scene.id);
    table.Add(row);
    row = Cells("baseline", d.baseline);
    row.insert(row.begin(), "");
    table.Add(row);
    out << Fixed("  (rendered in %.0f s", d.files.render_wall_seconds) << Fixed(", %.0f CPU s", d.files.render_cpu_seconds)
        << (d.files.from_cache ? ", from the cache)\n" : ")\n") << AnalysisText(d.analysis) << std::flush;
    json_draws.push_back({{"id", d.scene.id},
                          {"seed", d.scene.seed},
                          {"scene", d.scene.Summary()},
                          {"condition", DescribeFootage(c)},
                          {"render_wall_s", d.files.render_wall_seconds},
                          {"render_cpu_s", d.files.render_cpu_seconds},
                          {"core", ScoreJson(d.core)},
                          {"baseline", ScoreJson(d.baseline)},
                          {"analysis", AnalysisJson(d.analysis)}});
    draws.push_back(std::move(d));
  }

  // Over the draws: each tracker's percentiles, and the paired difference per draw.
  ordered_json summary;
  out << "\nover " << draws.size() << " draws (median, p95 of the per-draw px RMS; frames found of those in view; "
      << "silent wrong frames):\n";
  for (const bool core : {true, false}) {
    std::vector<double> rms;
    int in_view = 0, found = 0, wrong = 0, refused = 0, stated = 0, within = 0;
    for (const Draw& d : draws) {
      const Score& s = core ? d.core : d.baseline;
      rms.push_back(s.px_rms);
      in_view += s.in_view, found += s.found, wrong += s.silent_wrong, refused += !s.refusal.empty();
      stated += s.stated, within += s.within_stated;
    }
    const char* name = core ? "core" : "baseline";
    out << "  " << name << ": median " << Fixed("%.3f px", Quantile(rms, 0.5)) << ", p95 "
        << Fixed("%.3f px", Quantile(rms, 0.95)) << ", found " << found << "/" << in_view << ", silent wrong "
        << wrong << (refused ? ", refused " + std::to_string(refused) : "");
    if (stated > 0)
      out << "; its stated u_px holds the truth within 2.45 u (95 % expected) in " << within << " of " << stated
          << Fixed(" frames (%.1f %%)", 100.0 * within / stated);
    out << "\n";
    summary[name] = {{"px_rms_median", Quantile(rms, 0.5)}, {"px_rms_p95", Quantile(rms, 0.95)},
                     {"frames_in_view", in_view}, {"frames_found", found}, {"silent_wrong", wrong},
                     {"refused", refused}, {"frames_with_u", stated}, {"within_95_of_u", within}};
  }
  // analyse-track over the draws: per quantity, the draws scored, those within 3 stated u, and
  // the RMS pull; a rest position's |error| too (the goal: 0.02 mm on a sharp clip).
  std::map<std::string, std::vector<double>> pulls;
  std::vector<double> rest_mm;
  int unscored = 0;
  for (const Draw& d : draws) {
    unscored += d.analysis.pulls.empty();
    for (const AnalysisPull& p : d.analysis.pulls) {
      pulls[p.name].push_back(p.Pull());
      if (p.name == "Y") rest_mm.push_back(std::abs(p.error) * 1e3);
    }
  }
  out << "  analyse-track on the core's tracks (pull = (fitted - true)/stated u): ";
  ordered_json pull_summary;
  for (const auto& [name, values] : pulls) {
    int within = 0;
    double sum = 0;
    for (double v : values) within += std::abs(v) <= 3, sum += std::isfinite(v) ? v * v : 0;
    const double rms = std::sqrt(sum / values.size());
    out << name << " " << within << "/" << values.size() << " within 3u, RMS pull " << Fixed("%.2f", rms) << "; ";
    pull_summary[name] = {{"draws", values.size()}, {"within_3u", within}, {"rms_pull", rms}};
  }
  out << "rest |Y error| median " << Fixed("%.4f mm", Quantile(rest_mm, 0.5)) << ", max "
      << Fixed("%.4f mm", Quantile(rest_mm, 1.0)) << "; " << unscored << " draws without pulls\n";
  summary["analysis"] = {{"pulls", pull_summary}, {"rest_error_mm_median", Quantile(rest_mm, 0.5)},
                         {"draws_without_pulls", unscored}};
  std::vector<double> diff;
  const Draw* worst = nullptr;
  for (const Draw& d : draws) {
    diff.push_back(d.core.px_rms - d.baseline.px_rms);
    if (std::isfinite(diff.back()) && (!worst || diff.back() > worst->core.px_rms - worst->baseline.px_rms))
      worst = &d;
  }
  out << "  core - baseline (px RMS, paired per draw): median " << Fixed("%+.3f px", Quantile(diff, 0.5))
      << ", p95 " << Fixed("%+.3f px", Quantile(diff, 0.95));
  if (worst)
    out << "; worst draw " << worst->scene.id << Fixed(" (%+.3f px): ", worst->core.px_rms - worst->baseline.px_rms)
        << worst->scene.Summary();
  out << "\n";
  summary["core_minus_baseline"] = {{"px_rms_median", Quantile(diff, 0.5)},
                                    {"px_rms_p95", Quantile(diff, 0.95)},
                                    {"worst_draw", worst ? ordered_json(worst->scene.id) : ordered_json()}};
  if (!o.json.empty()) {
    const ordered_json doc = {{"format", "uphill-bench-random/1"},
                              {"seed", seed},
                              {"truth", "the renderer's projected centre per frame; x(t) of uphill::Motion "
                                        "(src/motion) at each tracker's stated time"},
                              {"draws", json_draws},
                              {"summary", summary}};
    WriteFileAtomically(o.json, doc.dump(2) + "\n");
    out << "wrote " << o.json << "\n";
  }
}

}  // namespace uphill::bench
