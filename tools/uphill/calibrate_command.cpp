// `uphill calibrate`: the camera that films the apparatus (src/vision/calibration.hpp).
//   calibrate camera IMAGES… --cols 9 --rows 6 --square 20mm -o cam.json
//   calibrate scene --camera cam.json --points POINTS.csv -o scene.json [--frame FRAME.png]
//   calibrate scene --camera cam.json --board-image TABLE.png --cols … --board-origin … -o scene.json
//   calibrate target --cols 9 --rows 6 --square 20mm -o board.svg|board.png
// The numbers are printed with their units; the files' formats are in calibration/README.md. The
// points file and the target: src/app/calibration_inputs.hpp.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "flag_checks.hpp"
#include "vision_program.hpp"
#if UPHILL_VISION_PROGRAM
#include <Eigen/Geometry>
#include <iostream>
#include <sstream>

#include "app/calibration_files.hpp"
#include "app/calibration_inputs.hpp"
#include "io/output_paths.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "vision/calibration.hpp"
#endif

namespace uphill::cli {
namespace {

struct TargetFlags {
  int cols = 9, rows = 6;
  std::string square;
};

struct CalibrateFlags {
  TargetFlags target;
  std::vector<std::string> images;
  std::string camera, points, frame, output;
  std::string board_image, board_origin, board_x_axis = "+x", board_y_axis = "-y";
  bool fit_k3 = false;
  std::string dpi = "300";
};

void AddTargetFlags(CLI::App* cmd, TargetFlags* f, bool square_required) {
  cmd->add_option("--cols", f->cols, "inner corners across the board (a board of 10×7 squares has 9×6)")
      ->capture_default_str();
  cmd->add_option("--rows", f->rows, "inner corners down the board")->capture_default_str();
  cmd->add_option("--square", f->square,
                  std::string("side of one square, with unit, e.g. 20mm (measure the print)") +
                      (square_required ? " (required)" : ""));
}

#if UPHILL_VISION_PROGRAM

ChessboardTarget Target(const TargetFlags& f) {
  if (f.square.empty()) throw InputError("--square", "is required (the side of one square, with unit, e.g. 20mm)");
  ChessboardTarget t{f.cols, f.rows, ParseQuantity(f.square, Dimension::kLength, "--square")};
  ValidateCalibrationTarget(t);
  return t;
}

// ---- camera ----

// -o checked before any work: never one of the inputs, never anything but a regular file.
void CheckOutput(const CalibrateFlags& f) {
  OutputPaths outputs;
  for (const std::string& image : f.images) outputs.AddInput(image, "the image");
  outputs.AddInput(f.camera, "the camera file");
  outputs.AddInput(f.points, "the points file");
  outputs.AddInput(f.frame, "the frame");
  outputs.AddInput(f.board_image, "the board image");
  outputs.CheckFile(f.output, "-o");
}

// Just before writing: the output's missing folders.
void MakeOutputFolder(const CalibrateFlags& f) {
  OutputPaths::CreateFolders(std::filesystem::path(f.output).parent_path().string());
}

void RunCamera(const CalibrateFlags& f) {
  const ChessboardTarget target = Target(f.target);
  if (f.images.empty()) throw InputError("IMAGES", "give the chessboard views (10 to 20 image files)");
  CheckOutput(f);
  CameraCalibrationOptions options;
  options.fit_k3 = f.fit_k3;
  const CameraCalibration c = CalibrateCameraFromFiles(f.images, target, options);
  MakeOutputFolder(f);
  WriteCameraFile(f.output, c.camera, c.Summary(target));  // first: the printout then describes a saved file
  std::cout << CameraCalibrationText(c, target, f.fit_k3);
  std::cout << "wrote " << f.output << "\n";
}

// ---- scene ----

// "+x", "-y", "+z" etc.: a unit vector of the apparatus frame.
Eigen::Vector3d Axis(const std::string& text, const std::string& flag) {
  if (text.size() == 2 && (text[0] == '+' || text[0] == '-') && text[1] >= 'x' && text[1] <= 'z') {
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    a[text[1] - 'x'] = text[0] == '+' ? 1 : -1;
    return a;
  }
  throw InputError(flag, "must be one of +x, -x, +y, -y, +z, -z (got '" + text + "')");
}

Eigen::Vector3d Point(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    values.push_back(ParseQuantity(item, Dimension::kLength, flag));
  if (values.size() != 3) throw InputError(flag, "must be x,y,z with units, e.g. 350mm,50mm,0mm");
  return {values[0], values[1], values[2]};
}

void RunScene(const CalibrateFlags& f) {
  CheckOutput(f);
  const CameraIntrinsics camera = ReadCameraFile(f.camera);
  SceneCalibrationResult r;
  SceneInputs inputs;  // what the scene file keeps of a points file (a board's corners are not kept)
  if (!f.board_image.empty()) {
    if (!f.points.empty()) throw InputError("--points/--board-image", "give one of them, not both");
    if (f.board_origin.empty()) throw InputError("--board-origin", "is required with --board-image");
    const Eigen::Vector3d x = Axis(f.board_x_axis, "--board-x-axis"), y = Axis(f.board_y_axis, "--board-y-axis");
    const Eigen::Vector3d origin = Point(f.board_origin, "--board-origin");
    r = CalibrateSceneFromBoardFile(camera, f.board_image, Target(f.target), origin, x, y);
  } else {
    if (f.points.empty()) throw InputError("--points", "is required (or --board-image)");
    r = CalibrateSceneFromPointsFile(camera, f.camera, f.points, f.frame, &inputs);
  }
  MakeOutputFolder(f);
  WriteSceneFile(f.output, r.scene, r.Summary(), inputs);  // first: the printout then describes a saved file
  std::cout << SceneCalibrationText(r, f.camera);
  std::cout << "wrote " << f.output << "\n";
}

// ---- target ----

void RunTarget(const CalibrateFlags& f) {
  const ChessboardTarget t = Target(f.target);
  const std::string extension = std::filesystem::path(f.output).extension().string();
  if (extension != ".svg" && extension != ".png")
    throw InputError("-o", "must end in .svg or .png (got '" + f.output + "')");
  CheckOutput(f);
  const double dpi = extension == ".png" ? ParseQuantity(f.dpi, Dimension::kDimensionless, "--dpi") : 0.0;
  std::cout << "wrote " << f.output << ": " << WriteChessboardTarget(f.output, t, dpi) << "\n";
}

#else  // uphill: the work runs in uphill-vision (vision_program.hpp)

void RunCamera(const CalibrateFlags&) { RunInVisionProgram(); }
void RunScene(const CalibrateFlags&) { RunInVisionProgram(); }
void RunTarget(const CalibrateFlags&) { RunInVisionProgram(); }

#endif

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto flags = std::make_shared<CalibrateFlags>();
  CLI::App* calibrate = app.add_subcommand("calibrate", "Camera calibration: intrinsics, pose in the apparatus, target");
  calibrate->require_subcommand(1);

  CLI::App* camera = calibrate->add_subcommand("camera", "Intrinsics and lens distortion from chessboard views");
  camera->add_option("images", flags->images, "image files of the chessboard (10 to 20 views)")->required();
  AddTargetFlags(camera, &flags->target, true);
  camera->add_flag("--fit-k3", flags->fit_k3, "also fit the distortion coefficient k3 (wide-angle lenses)");
  camera->add_option("-o,--output", flags->output, "camera file to write (JSON)")->required();
  camera->callback([flags] { RunCamera(*flags); });

  CLI::App* scene = calibrate->add_subcommand("scene", "Camera pose in the apparatus frame from points of known position");
  scene->add_option("--camera", flags->camera, "camera file from `calibrate camera`")->required();
  scene->add_option("--points", flags->points, "CSV: u,v (px), x,y,z with length unit (x_mm) per point");
  scene->add_option("--frame", flags->frame, "a frame of the video: its size must be the camera's");
  scene->add_option("--board-image", flags->board_image, "instead of --points: an image of a chessboard lying in the scene");
  AddTargetFlags(scene, &flags->target, false);
  scene->add_option("--board-origin", flags->board_origin, "with --board-image: first inner corner, x,y,z with units");
  scene->add_option("--board-x-axis", flags->board_x_axis, "with --board-image: apparatus axis along the board's rows")
      ->capture_default_str();
  scene->add_option("--board-y-axis", flags->board_y_axis, "with --board-image: apparatus axis down the board's columns")
      ->capture_default_str();
  scene->add_option("-o,--output", flags->output, "scene file to write (JSON)")->required();
  scene->callback([flags, scene] {
    // The chessboard's flags belong to --board-image; --frame to --points.
    const bool board = !flags->board_image.empty();
    for (const char* flag : {"--cols", "--rows", "--square", "--board-origin", "--board-x-axis", "--board-y-axis"})
      RefuseIgnored(scene, flag, !board, "applies only with --board-image (a chessboard lying in the scene)");
    RefuseIgnored(scene, "--frame", board, "applies only with --points (the board image itself is checked)");
    RefuseEmpty(scene, "--points", flags->points, "a CSV of points");
    RefuseEmpty(scene, "--board-image", flags->board_image, "an image file");
    RunScene(*flags);
  });

  CLI::App* target = calibrate->add_subcommand("target", "Write a chessboard target to print (SVG or PNG)");
  AddTargetFlags(target, &flags->target, true);
  target->add_option("--dpi", flags->dpi, "PNG only: printer resolution (dots per inch)")->capture_default_str();
  target->add_option("-o,--output", flags->output, "file to write: .svg (exact size in mm) or .png")->required();
  target->callback([flags, target] {
    RefuseIgnored(target, "--dpi", std::filesystem::path(flags->output).extension() == ".svg",
                  "applies to a .png target only (an SVG has its size in mm)");
    RunTarget(*flags);
  });
}

}  // namespace uphill::cli
