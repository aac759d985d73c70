// make_video: writes a synthetic clip of the default apparatus (synthetic_clip.hpp,
// DefaultClipSetup) with its exact ground truth, the camera and scene files of the camera that
// filmed it, and chessboard images for `uphill calibrate camera`. Seeded: the same flags give the
// same files.
//
// Usage: make_video OUT_DIR [--width 1280 --height 720] [--frames 60] [--fps 30] [--blur 8]
//        [--noise 2] [--flicker 0.01] [--lossless] [--spheroid] [--boards 12] [--seed 1]
// Writes OUT_DIR/clip.mp4 (H.264; clip.avi, FFV1, with --lossless), truth.csv, cam.json,
// scene.json, points.csv (the apparatus points of calibration/README.md in view, O, the rails at
// the crossbar, the feet on the table, marks at 300/600/900 mm, with their exact pixels: the
// POINTS.csv of `uphill calibrate scene`, and the clicks of the page's end-to-end test),
// boards/board_NN.png, and prints the `uphill track` command for the clip.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.hpp"
#include "model/input_error.hpp"
#include "vision/apparatus_points.hpp"
#include "vision/chessboard_render.hpp"
#include "vision/synthetic_clip.hpp"

namespace {

namespace fs = std::filesystem;
using namespace uphill;

struct Flags {
  std::string out;
  int width = 1280, height = 720, frames = 60, blur = 1, boards = 12;
  double fps = 30, noise = 0, flicker = 0;
  bool lossless = false, spheroid = false;
  unsigned seed = 1;
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
  fs::create_directories(f.out);
  ClipSettings settings;
  settings.frames = f.frames;
  settings.fps = f.fps;
  settings.blur_samples = f.blur;
  settings.noise_sigma = f.noise;
  settings.flicker = f.flicker;
  settings.seed = f.seed;
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const Motion motion(setup.scene, setup.x0);
  const std::string video = (fs::path(f.out) / (f.lossless ? "clip.avi" : "clip.mp4")).string();
  const std::vector<ClipTruth> truth = RenderClip(renderer, motion, settings, video);
  WriteClipTruthCsv((fs::path(f.out) / "truth.csv").string(), truth);
  CalibrationSummary summary;
  summary.method = "synthetic camera of tools/make_video (exact)";
  summary.verdict = "exact";
  summary.reasons = {"the camera that rendered the clip: no calibration error"};
  WriteCameraFile((fs::path(f.out) / "cam.json").string(), setup.calibration.camera, summary);
  WriteSceneFile((fs::path(f.out) / "scene.json").string(), setup.calibration, summary);
  std::string points = "name,u,v,x_mm,y_mm,z_mm\n";
  for (const ApparatusPoint& p : VisibleApparatusPoints(
           setup.calibration.camera, setup.calibration.pose,
           ApparatusCalibrationPoints(setup.scene.rails(), setup.apparatus.crossbar_x, setup.apparatus.table_z,
                                      {0.3, 0.6, 0.9}))) {
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
  std::cout << "wrote " << video << " (" << truth.size() << " frames), truth.csv, cam.json, scene.json, points.csv";
  if (f.boards > 0) std::cout << ", boards/ (" << f.boards << " chessboard views, 9x6 inner corners, 20 mm)";
  std::cout << "\ntrack it with:\n  uphill track " << video << " --camera " << f.out << "/cam.json --scene " << f.out
            << "/scene.json " << body_flags << " --L 1000mm --H 100mm --D 150mm --rod-diameter 8mm -o " << f.out
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
