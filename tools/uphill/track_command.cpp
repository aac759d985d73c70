// `uphill track VIDEO --camera cam.json --scene scene.json [scene flags] -o track.csv`: the ball's
// centre in every frame (src/vision/video_tracking.hpp, ball_tracker.hpp), as the track CSV and
// its sidecar JSON (data/README.md, "Track CSV"); optionally an overlay video and the analysis of
// the track (src/vision/track_analysis.hpp, written beside the CSV as `uphill analyse-track` does).
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "scene_flags.hpp"
#include "vision_program.hpp"
#if UPHILL_VISION_PROGRAM
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/track_analysis_output.hpp"
#include "app/track_video_file.hpp"
#include "progress_bars.hpp"
#include "io/configuration.hpp"
#include "io/output_paths.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "vision/track_analysis.hpp"
#include "vision/track_table.hpp"
#endif

namespace uphill::cli {
namespace {

struct TrackFlags {
  SceneFlags scene;
  std::string video, camera, scene_file, out, init, overlay, exposure, readout, transfer = "srgb";
  std::optional<double> min_quality;  // unset: TrackerOptions' default
  bool analyse = false, quiet = false;
};

#if UPHILL_VISION_PROGRAM

// "u,v" in raw pixels (plain numbers: pixels are the image's own unit).
Eigen::Vector2d ParsePixel(const std::string& text) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos) throw InputError("--init", "must be u,v in raw pixels (got '" + text + "')");
  try {
    size_t used_u = 0, used_v = 0;
    const std::string us = text.substr(0, comma), vs = text.substr(comma + 1);
    const double u = std::stod(us, &used_u), v = std::stod(vs, &used_v);
    if (used_u != us.size() || used_v != vs.size() || !std::isfinite(u) || !std::isfinite(v)) throw std::invalid_argument("");
    return {u, v};
  } catch (const std::exception&) {
    throw InputError("--init", "must be u,v in raw pixels, two numbers (got '" + text + "')");
  }
}

// Where --analyse writes: the folder of the track CSV.
std::string AnalysisFolder(const TrackFlags& f) {
  const std::string folder = std::filesystem::path(f.out).parent_path().string();
  return folder.empty() ? "." : folder;
}

void Run(const TrackFlags& f) {
  if (f.camera.empty()) throw InputError("--camera", "is required (the camera file of `uphill calibrate camera`)");
  if (f.scene_file.empty()) throw InputError("--scene", "is required (the scene file of `uphill calibrate scene`)");
  if (f.out.empty()) throw InputError("-o", "is required (the track CSV to write)");
  const Configuration configuration = ParseConfiguration(FlagSource(f.scene));
  const Scene scene = configuration.MakeScene();
  // Every output checked before any work: never an input, never anything but a regular file.
  OutputPaths outputs;
  outputs.AddInput(f.video, "the input video");
  outputs.AddInput(f.camera, "the camera file");
  outputs.AddInput(f.scene_file, "the scene file");
  outputs.CheckFile(f.out, "-o");
  outputs.CheckFile(f.out + ".json", "-o (its sidecar)");
  if (!f.overlay.empty()) outputs.CheckFile(f.overlay, "--overlay");
  if (f.analyse) outputs.CheckFolder(AnalysisFolder(f), "-o (with --analyse)", TrackAnalysisFiles());

  TrackVideoFileOptions options;
  options.overlay_path = f.overlay;
  if (!f.init.empty()) options.init_uv = ParsePixel(f.init);
  if (!f.exposure.empty()) options.exposure = ParseQuantity(f.exposure, Dimension::kTime, "--exposure");
  if (f.readout == "auto") options.measure_readout = true;
  else if (!f.readout.empty()) options.readout = ParseQuantity(f.readout, Dimension::kTime, "--readout");
  options.transfer = ParseVideoTransfer(f.transfer, "--transfer");
  if (f.min_quality) options.min_report_quality = *f.min_quality;
  const bool bar = !f.quiet && isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  FrameProgressCallback progress;
  if (bar)
    progress = [start](int done, long total) {
      if (done % 5 != 0 && done != total) return;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "\r%s ", FrameProgressText(done, total, elapsed).c_str());
      std::fflush(stderr);
    };
  const TrackResult result = TrackVideoFile(f.video, f.camera, f.scene_file, scene, options, progress);
  if (bar) std::fprintf(stderr, "\n");
  WriteTrack(f.out, result, {f.video, f.camera, f.scene_file, scene.body().Name()});

  int found = 0;
  double quality = 0;
  for (const auto& r : result.rows)
    if (r.ball.found) ++found, quality += r.ball.quality;
  std::cout << f.video << ": " << result.rows.size() << " frames, ball found in " << found << " (mean quality "
            << (found ? quality / found : 0.0) << ")\n"
            << "wrote " << f.out << " and " << f.out << ".json";
  if (!f.overlay.empty()) std::cout << " and " << f.overlay;
  std::cout << "\n";
  if (result.partial) {
    std::cerr << "uphill: " << f.video << ": partial track: " << result.partial_reason << "\n";
    // A cut video, a camera that moved, no body, a changed exposure are bad input; a ball that
    // drops out of view at the end is how runs end.
    if (result.input_problem) ExitStatus() = 2;
  }
  if (f.analyse) {
    // The same analysis as `uphill analyse-track OUT [scene flags] -o <OUT's folder>`, default options.
    const TrackAnalysis analysis = AnalyseTrack(ReadTrackFile(f.out), scene);
    std::cout << "\n" << TrackAnalysisTable(analysis);
    WriteTrackAnalysis(analysis, AnalysisFolder(f));
    std::cout << "wrote " << AnalysisFolder(f) << "/track_analysis.json and its figures\n";
  }
}

#else  // uphill: the work runs in uphill-vision (vision_program.hpp)

void Run(const TrackFlags&) { RunInVisionProgram(); }

#endif

}  // namespace

void AddTrackCommand(CLI::App& app) {
  auto flags = std::make_shared<TrackFlags>();
  CLI::App* cmd = app.add_subcommand("track", "Ball centre in every frame of a calibrated video -> track CSV");
  cmd->add_option("video", flags->video, "the video file (any format FFmpeg reads)")->required();
  cmd->add_option("--camera", flags->camera, "camera file (uphill calibrate camera)");
  cmd->add_option("--scene", flags->scene_file, "scene file: the camera's pose (uphill calibrate scene)");
  AddSceneFlags(cmd, &flags->scene);
  cmd->add_option("-o,--out", flags->out, "track CSV to write (and <csv>.json beside it)");
  cmd->add_option("--init", flags->init, "u,v: raw pixel near the ball's centre in the first frame (optional)");
  cmd->add_option("--exposure", flags->exposure,
                  "exposure time per frame, with unit (e.g. 8.33ms); default: measured from the motion blur");
  cmd->add_option("--readout", flags->readout,
                  "rolling shutter: time from the first to the last row, with unit (e.g. 25ms), or auto (measured from "
                  "the ball's shear: a phone); default 0 (global shutter)");
  cmd->add_option("--transfer", flags->transfer, "the video's transfer curve: srgb (cameras, default) or linear");
  cmd->add_option("--min-quality", flags->min_quality,
                  "positions of a lower quality (0 to 1) are doubted: left out where they lie off the motion of "
                  "the frames around them (default 0.45, docs/track.md); 0 doubts none");
  cmd->add_option("--overlay", flags->overlay, "write the video with the fitted outline drawn (.mp4)");
  cmd->add_flag("--analyse", flags->analyse, "then analyse the track (release, rest, fall-off, model fit)");
  cmd->add_flag("--quiet", flags->quiet, "no progress bar");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
