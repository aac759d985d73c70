// make_video: writes a synthetic clip of the default apparatus (synthetic_clip.hpp,
// DefaultClipSetup) with its exact ground truth, the camera and scene files of the camera that
// filmed it, and chessboard images for `uphill calibrate camera`. Seeded: the same flags give the
// same files.
//
// Usage: make_video OUT_DIR [--width 1280 --height 720] [--frames 60] [--fps 30] [--blur 8]
//        [--noise 2] [--flicker 0.01] [--lossless] [--spheroid] [--boards 12] [--seed 1]
//        [--D 150] [--x0 MM | --x0-band F] [--mu 0] [--release-time 0] [--seconds S | --until-end]
//        [--name clip] [--marks 300,600,900] [--bare]
// Writes OUT_DIR/NAME.mp4 (H.264; NAME.avi, FFV1, with --lossless), NAME.truth.csv (truth.csv
// for the default name), cam.json, scene.json, points.csv (the apparatus points of
// calibration/README.md that a person can see in the first frame, O, the rails at the crossbar,
// the crossbar's feet on the table, the tape marks, with their exact pixels: the POINTS.csv of
// `uphill calibrate scene`, and the clicks of the page's end-to-end test; a point hidden behind a
// rod, the crossbar or the ball is left out), boards/board_NN.png, and prints the `uphill track`
// command for the clip. A trial of an experiment (data/series3-video): the rail separation D, the
// release position and the rolling resistance μ of the motion (the ODE method when μ > 0), held
// at rest until --release-time; --x0-band F releases at band.high + F·(band.high − X) of the rest
// band of μ (F < 0: inside the band, the body stays; F > 0: beyond it, it rolls up and falls off);
// --until-end makes the clip last until the motion has ended (+0.3 s), or 1 s at rest.
// The apparatus carries what a lab marks (synthetic_clip.hpp's ClipApparatus): black tape round
// both rods at --marks (mm from O, horizontally), the crossbar's feet and a ruler on the table;
// --bare draws none of them.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.hpp"
#include "model/input_error.hpp"
#include "vision/apparatus_points.hpp"
#include "vision/chessboard_render.hpp"
#include "footage/synthetic_clip.hpp"

namespace {

namespace fs = std::filesystem;
using namespace uphill;

struct Flags {
  std::string out;
  int width = 1280, height = 720, frames = 60, blur = 1, boards = 12;
  double fps = 30, noise = 0, flicker = 0;
  bool lossless = false, spheroid = false, until_end = false;
  unsigned seed = 1;
  double D_mm = 150, mu = 0, release_time = 0, seconds = 0;
  std::optional<double> x0_mm, x0_band;
  std::string name = "clip";
  std::vector<double> marks_mm = {300, 600, 900};
  bool bare = false;
};

void Run(const Flags& f) {
  ClipSetup setup = DefaultClipSetup(f.width, f.height);
  std::string body_flags = "--body sphere --R 25.4mm";
  if (f.spheroid) {
    // The lab's 2 x 1.25 x 1.25 inch spheroid on the same rails.
    setup.scene = Scene(Body::Spheroid(0.015875, 0.0254), setup.scene.rails(), setup.scene.rod_radius());
    setup.x0 = 0.97 * *setup.scene.x_eq();
    body_flags = "--body spheroid --a 15.875mm --b 25.4mm";
  }
  if (f.x0_band) {
    if (f.spheroid) throw InputError("--x0-band", "applies to the ball (not --spheroid)");
    setup = TrialClipSetup(f.width, f.height, f.D_mm * 1e-3, f.mu, *f.x0_band);
  } else if (f.D_mm != 150) {
    setup.scene = Scene(setup.scene.body(),
                        Rails::FromApparatus(1.0, 0.1, f.D_mm * 1e-3, LConvention::kHorizontal), setup.scene.rod_radius());
    setup.x0 = 0.97 * *setup.scene.x_eq();
  }
  if (f.x0_mm) setup.x0 = *f.x0_mm * 1e-3;
  MotionOptions motion_options;
  motion_options.mu = f.mu;
  if (f.mu > 0) motion_options.method = MotionMethod::kOde;
  const Motion motion(setup.scene, setup.x0, motion_options);
  fs::create_directories(f.out);
  ClipSettings settings;
  settings.frames = f.frames;
  settings.fps = f.fps;
  settings.release_time = f.release_time;
  if (f.seconds > 0) settings.frames = static_cast<int>(std::ceil(f.seconds * f.fps));
  if (f.until_end) {
    const double end = std::isfinite(motion.end_time()) ? motion.end_time() + 0.3 : 1.0;
    settings.frames = static_cast<int>(std::ceil((f.release_time + end) * f.fps));
  }
  settings.blur_samples = f.blur;
  settings.noise_sigma = f.noise;
  settings.flicker = f.flicker;
  settings.seed = f.seed;
  std::vector<double> marks_m;
  for (double mm : f.marks_mm) marks_m.push_back(mm * 1e-3);
  if (!f.bare) {
    setup.apparatus.tape_marks_x = marks_m;
    setup.apparatus.feet = setup.apparatus.ruler = true;
  }
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  std::cout << "x0 = " << setup.x0 * 1e3 << " mm";
  if (const auto band = setup.scene.Rest(f.mu)) std::cout << ", rest band of mu = " << f.mu << ": [" << band->low * 1e3 << ", " << band->high * 1e3 << "] mm";
  std::cout << ", X = " << setup.scene.x_eq().value_or(0) * 1e3 << " mm\n";
  const std::string video = (fs::path(f.out) / (f.name + (f.lossless ? ".avi" : ".mp4"))).string();
  const std::vector<ClipTruth> truth = RenderClip(renderer, motion, settings, video);
  const std::string truth_name = f.name == "clip" ? "truth.csv" : f.name + ".truth.csv";
  WriteClipTruthCsv((fs::path(f.out) / truth_name).string(), truth);
  CalibrationSummary summary;
  summary.method = "synthetic camera of tools/make_video (exact)";
  summary.verdict = "exact";
  summary.reasons = {"the camera that rendered the clip: no calibration error"};
  WriteCameraFile((fs::path(f.out) / "cam.json").string(), setup.calibration.camera, summary);
  WriteSceneFile((fs::path(f.out) / "scene.json").string(), setup.calibration, summary);
  // A point is seen where the first surface on its ray lies within a rod's or a foot's radius of
  // it (plus 2 mm): on the rod, the tape or the post it marks, not on something in front of it.
  const double reach =
      std::max({setup.scene.rod_radius(), setup.apparatus.min_rod_radius, setup.apparatus.foot_radius}) + 0.002;
  const MotionSample first = motion.At(0);
  std::string points = "name,u,v,x_mm,y_mm,z_mm\n";
  for (const ApparatusPoint& p : VisibleApparatusPoints(
           setup.calibration.camera, setup.calibration.pose,
           ApparatusCalibrationPoints(setup.scene.rails(), setup.apparatus.crossbar_x, setup.apparatus.table_z,
                                      f.bare ? std::vector<double>{} : marks_m))) {
    if (!renderer.Sees(p.position, {Eigen::Vector2d(first.x, first.z)}, reach)) continue;
    char line[200];
    std::snprintf(line, sizeof line, "%s,%.6f,%.6f,%.6f,%.6f,%.6f\n", p.name.c_str(), p.pixel.x(), p.pixel.y(),
                  p.position.x() * 1e3, p.position.y() * 1e3, p.position.z() * 1e3);
    points += line;
  }
  WriteFileAtomically((fs::path(f.out) / "points.csv").string(), points);
  if (f.boards > 0) {
    const ChessboardTarget target;  // 9 x 6 inner corners, 20 mm squares
    const ChessboardRenderer boards(setup.calibration.camera, target);
    fs::create_directories(fs::path(f.out) / "boards");
    ChessboardRenderOptions options;
    options.noise_sigma = f.noise;
    options.seed = f.seed;
    int k = 0;
    for (const CameraPose& pose : RandomBoardPoses(setup.calibration.camera, target, f.boards, f.seed)) {
      char name[32];
      std::snprintf(name, sizeof name, "board_%02d.png", k++);
      cv::imwrite((fs::path(f.out) / "boards" / name).string(), boards.Render(pose, options).image);
    }
  }
  std::cout << "wrote " << video << " (" << truth.size() << " frames), " << truth_name << ", cam.json, scene.json, points.csv";
  if (f.boards > 0) std::cout << ", boards/ (" << f.boards << " chessboard views, 9x6 inner corners, 20 mm)";
  std::cout << "\ntrack it with:\n  uphill track " << video << " --camera " << f.out << "/cam.json --scene " << f.out
            << "/scene.json " << body_flags << " --L 1000mm --H 100mm --D " << f.D_mm << "mm --rod-diameter 8mm -o " << f.out
            << "/track.csv\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"make_video: a synthetic clip of the rolling ball with exact ground truth"};
  Flags f;
  app.add_option("out", f.out, "output folder")->required();
  app.add_option("--width", f.width)->capture_default_str();
  app.add_option("--height", f.height)->capture_default_str();
  app.add_option("--frames", f.frames)->capture_default_str();
  app.add_option("--fps", f.fps)->capture_default_str();
  app.add_option("--blur", f.blur, "sub-exposure renders averaged (motion blur); 1: sharp")->capture_default_str();
  app.add_option("--noise", f.noise, "sensor noise, grey levels")->capture_default_str();
  app.add_option("--flicker", f.flicker, "relative std of a per-frame gain")->capture_default_str();
  app.add_flag("--lossless", f.lossless, "FFV1 in .avi instead of H.264 in .mp4");
  app.add_flag("--spheroid", f.spheroid, "the lab's 2 x 1.25 x 1.25 in spheroid instead of the 2 in ball");
  app.add_option("--boards", f.boards, "chessboard calibration images")->capture_default_str();
  app.add_option("--seed", f.seed)->capture_default_str();
  app.add_option("--D", f.D_mm, "rail separation at the crossbar, mm (L = 1000 mm, H = 100 mm)")->capture_default_str();
  app.add_option("--x0", f.x0_mm, "release position, mm (default 0.97 X)");
  app.add_option("--x0-band", f.x0_band, "release at band.high + F (band.high - X) of mu's rest band");
  app.add_option("--mu", f.mu, "rolling resistance of the motion")->capture_default_str();
  app.add_option("--release-time", f.release_time, "s at rest before the release")->capture_default_str();
  app.add_option("--seconds", f.seconds, "clip length, s (instead of --frames)");
  app.add_flag("--until-end", f.until_end, "clip lasts until the motion ends (+0.3 s; 1 s when at rest)");
  app.add_option("--name", f.name, "file stem of the clip")->capture_default_str();
  app.add_option("--marks", f.marks_mm, "tape marks on both rods, mm from O (horizontal)")->delimiter(',')->capture_default_str();
  app.add_flag("--bare", f.bare, "no tape marks, feet or ruler: the rails and the crossbar alone");
  CLI11_PARSE(app, argc, argv);
  try {
    Run(f);
  } catch (const uphill::InputError& e) {
    std::cerr << "make_video: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "make_video: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
