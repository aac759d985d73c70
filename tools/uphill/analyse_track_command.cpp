// `uphill analyse-track TRACK.csv [scene flags] [--g] [--fit g|mu] [--u-x] [-o DIR]`: the events
// of a measured ball track (release, direction, turning points, rest, fall-off) and the model
// motion fitted to it (src/vision/track_analysis.hpp), as a table with units; with -o also
// DIR/track_analysis.json and the figures track_x_vs_t and track_residuals.
#include <memory>

#include "commands.hpp"
#include "scene_flags.hpp"
#include "vision_program.hpp"
#if UPHILL_VISION_PROGRAM
#include <cmath>
#include <iostream>

#include "app/track_analysis_output.hpp"
#include "io/output_paths.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "vision/track_analysis.hpp"
#include "vision/track_table.hpp"
#endif

namespace uphill::cli {
namespace {

// TrackAnalysisOptions' defaults (asserted in Run, where the header is seen).
constexpr double kTrackerFloorPx = 0.08, kTrackerBlur = 0.007, kFitSystematicScale = 0.8;

struct AnalyseTrackFlags {
  SceneFlags scene;
  std::string track, g = "9.80665m/s2", fit = "g", u_x = "0.5mm", output;
  double tracker_floor_px = kTrackerFloorPx, tracker_blur = kTrackerBlur, fit_systematic_scale = kFitSystematicScale;
  bool json = false;
};

#if UPHILL_VISION_PROGRAM
void Run(const AnalyseTrackFlags& f) {
  static_assert(TrackAnalysisOptions{}.tracker_floor_px == kTrackerFloorPx &&
                TrackAnalysisOptions{}.tracker_blur == kTrackerBlur &&
                TrackAnalysisOptions{}.fit_systematic_scale == kFitSystematicScale);
  const Scene scene = ParseConfiguration(FlagSource(f.scene)).MakeScene();
  TrackAnalysisOptions o;
  o.g = ParseQuantity(f.g, Dimension::kAcceleration, "--g");
  RequireGravity("--g", o.g);
  o.u_x = ParseQuantity(f.u_x, Dimension::kLength, "--u-x");
  RequirePositiveLength("--u-x", o.u_x);
  if (!(f.tracker_floor_px >= 0.0 && std::isfinite(f.tracker_floor_px)))
    throw InputError("--tracker-floor-px", "must be >= 0 (pixels)");
  if (!(f.tracker_blur >= 0.0 && std::isfinite(f.tracker_blur)))
    throw InputError("--tracker-blur", "must be >= 0 (pixels of error per pixel moved per frame)");
  if (!(f.fit_systematic_scale >= 0.0 && std::isfinite(f.fit_systematic_scale)))
    throw InputError("--fit-systematic-scale", "must be >= 0 (a share of the tracker's systematic error)");
  o.tracker_floor_px = f.tracker_floor_px;
  o.tracker_blur = f.tracker_blur;
  o.fit_systematic_scale = f.fit_systematic_scale;
  o.fit = ParseTrackFitParameter(f.fit, "--fit");
  if (!f.output.empty()) {  // checked before any work
    OutputPaths outputs;
    outputs.AddInput(f.track, "the track file");
    outputs.CheckFolder(f.output, "-o", TrackAnalysisFiles());
  }
  const Track track = ReadTrackFile(f.track);
  const TrackAnalysis analysis = AnalyseTrack(track, scene, o);
  if (f.json) {
    std::cout << TrackAnalysisJson(analysis).dump(2) << "\n";
  } else {
    std::cout << TrackAnalysisTable(analysis);
  }
  if (!f.output.empty()) {
    WriteTrackAnalysis(analysis, f.output);
    if (!f.json) std::cout << "wrote " << f.output << "/track_analysis.json and the figures track_x_vs_t"
                           << (analysis.fit.available ? ", track_residuals" : "") << " (.svg, .png, .gp, .dat)\n";
  }
}

#else  // uphill: the work runs in uphill-vision (vision_program.hpp)

void Run(const AnalyseTrackFlags&) { RunInVisionProgram(); }

#endif

}  // namespace

void AddAnalyseTrackCommand(CLI::App& app) {
  auto flags = std::make_shared<AnalyseTrackFlags>();
  CLI::App* cmd = app.add_subcommand(
      "analyse-track", "Events (release, turning points, rest, fall-off) and the model fit of a ball track CSV");
  cmd->add_option("track", flags->track, "track CSV written by `uphill track` ('-' reads stdin)")->required();
  AddSceneFlags(cmd, &flags->scene);
  cmd->add_option("--g", flags->g, "gravitational acceleration, e.g. 9.81m/s2 (with --fit g: the reference)")
      ->capture_default_str();
  cmd->add_option("--fit", flags->fit, "third fit parameter besides x0, t0: g (effective g) or mu")
      ->capture_default_str();
  cmd->add_option("--u-x", flags->u_x, "standard uncertainty of a tracked position, e.g. 0.3mm")->capture_default_str();
  cmd->add_option("--tracker-floor-px", flags->tracker_floor_px,
                  "the tracker's systematic error of a position at rest, 1 sigma, raw pixels")
      ->capture_default_str();
  cmd->add_option("--tracker-blur", flags->tracker_blur,
                  "the tracker's systematic error added per pixel the ball moves in one frame interval")
      ->capture_default_str();
  cmd->add_option("--fit-systematic-scale", flags->fit_systematic_scale,
                  "the share of the tracker's systematic error a moving fit's x0, t0, g or mu carry "
                  "(1: all of it; positions at rest always carry all)")
      ->capture_default_str();
  cmd->add_option("-o,--output", flags->output, "folder for track_analysis.json and the figures (created if needed)");
  cmd->add_flag("--json", flags->json, "print track_analysis.json instead of the table");
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
