// Calibration (src/vision/calibration.hpp) against known ground truth: chessboard views rendered
// from a known camera (src/vision/chessboard_render.hpp), and apparatus points projected through
// a known pose.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "model/input_error.hpp"
#include "vision/calibration.hpp"
#include "vision/chessboard_render.hpp"
#include "vision/decode_limits.hpp"
#include "oversized_media_support.hpp"
#include "vision_test_support.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

// 1280×720, fx = 1000 px, fy = 1004 px, cx = 646.5 px, cy = 353 px, k1 = −0.1, k2 = 0.015.
CameraIntrinsics TrueCamera() { return {1280, 720, 1000, 1004, 646.5, 353.0, {-0.1, 0.015, 0, 0, 0}}; }

const ChessboardTarget kTarget{9, 6, 0.025};
constexpr double kDegree = 3.14159265358979323846 / 180;


// Twelve views rendered once for the suite (the rendering dominates the test's time).
class CameraCalibrationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const ChessboardRenderer renderer(TrueCamera(), kTarget);
    ChessboardRenderOptions options;
    options.supersampling = 3;
    options.blur_sigma_px = 0.7;
    options.noise_sigma = 1.5;
    const std::vector<CameraPose> poses = RandomBoardPoses(TrueCamera(), kTarget, 12, 2024);
    views_ = new std::vector<ChessboardView>;
    for (size_t i = 0; i < poses.size(); ++i) {
      options.seed = static_cast<std::uint32_t>(i + 1);
      views_->push_back(renderer.Render(poses[i], options));
    }
  }
  static void TearDownTestSuite() {
    delete views_;
    views_ = nullptr;
  }
  static std::vector<NamedImage> Named() {
    std::vector<NamedImage> out;
    for (size_t i = 0; i < views_->size(); ++i) out.push_back({"view" + std::to_string(i) + ".png", (*views_)[i].image});
    return out;
  }
  static std::vector<ChessboardView>* views_;
};
std::vector<ChessboardView>* CameraCalibrationTest::views_ = nullptr;

TEST_F(CameraCalibrationTest, DetectedCornersMatchTheRenderedGroundTruth) {
  double worst = 0, sum = 0;
  size_t n = 0;
  for (const auto& view : *views_) {
    const std::vector<Eigen::Vector2d> found = FindChessboardCorners(view.image, kTarget);
    ASSERT_EQ(found.size(), view.corners.size());
    // Same order as the ground truth (the detector's start corner is disambiguated by colour).
    for (size_t i = 0; i < found.size(); ++i) {
      worst = std::max(worst, (found[i] - view.corners[i]).norm());
      sum += (found[i] - view.corners[i]).squaredNorm();
      ++n;
    }
  }
  // px: detector and rasterisation error at 3× supersampling (measured 0.05 px RMS, 0.24 px worst)
  EXPECT_LT(std::sqrt(sum / n), 0.1);
  EXPECT_LT(worst, 0.4);
}

TEST_F(CameraCalibrationTest, RecoversTheIntrinsicsOfTheRenderingCamera) {
  const CameraCalibration result = CalibrateCamera(Named(), kTarget);
  const CameraIntrinsics truth = TrueCamera();
  EXPECT_EQ(result.camera.width, 1280);
  EXPECT_EQ(result.camera.height, 720);
  EXPECT_NEAR(result.camera.fx / truth.fx, 1, 0.005);
  EXPECT_NEAR(result.camera.fy / truth.fy, 1, 0.005);
  EXPECT_NEAR(result.camera.cx, truth.cx, 3);
  EXPECT_NEAR(result.camera.cy, truth.cy, 3);
  ASSERT_EQ(result.camera.distortion.size(), 5u);
  EXPECT_NEAR(result.camera.distortion[0], -0.1, 0.01);
  EXPECT_EQ(result.camera.distortion[4], 0);  // k3 fixed by default
  EXPECT_LT(result.rms_px, 0.2);
  EXPECT_EQ(result.views_used, 12);
  EXPECT_GE(result.coverage, 0.6);
  EXPECT_EQ(result.verdict, "good") << (result.reasons.empty() ? "" : result.reasons.front());
  // The undistorted image agrees with the true camera's over the whole image, not only in fx, fy.
  double worst = 0;
  for (double u : {0.0, 640.0, 1279.0})
    for (double v : {0.0, 360.0, 719.0}) {
      const Eigen::Vector2d n = UndistortPixel(truth, {u, v});
      worst = std::max(worst, (ProjectCameraPoint(result.camera, {n.x(), n.y(), 1}) - Eigen::Vector2d(u, v)).norm());
    }
  EXPECT_LT(worst, 2.0);  // px
  for (const auto& v : result.views) EXPECT_GT(v.tilt_deg, 10);
  const CalibrationSummary summary = result.Summary(kTarget);
  EXPECT_EQ(summary.inputs.size(), 12u);
}

// Issue 11: the same image given 12 times counted as 12 views. A view that is pixel for pixel an
// earlier one (the same file twice, or a copy) is refused, naming both.
TEST_F(CameraCalibrationTest, TheSameImageTwiceIsRefused) {
  std::vector<NamedImage> images = Named();
  images.push_back({"copy_of_view3.png", images[3].image.clone()});
  const std::string message = InputErrorOf([&] { CalibrateCamera(images, kTarget); });
  EXPECT_NE(message.find("copy_of_view3.png: is the same image as view3.png"), std::string::npos) << message;
  std::vector<NamedImage> twelve(12, images[0]);
  for (size_t i = 0; i < twelve.size(); ++i) twelve[i].name = "shot" + std::to_string(i) + ".png";
  EXPECT_NE(InputErrorOf([&] { CalibrateCamera(twelve, kTarget); }).find("shot1.png: is the same image as shot0.png"),
            std::string::npos);
}

TEST_F(CameraCalibrationTest, ImagesWithoutABoardAreRejectedAndNamed) {
  std::vector<NamedImage> images = Named();
  images.resize(10);
  cv::Mat blank(720, 1280, CV_8U, cv::Scalar(128));
  cv::randn(blank, 128, 20);
  images.push_back({"empty_table.png", blank});
  const CameraCalibration result = CalibrateCamera(images, kTarget);
  EXPECT_EQ(result.views_used, 10);
  EXPECT_FALSE(result.views.back().used);
  EXPECT_NE(result.views.back().rejected_because.find("not found"), std::string::npos);
  EXPECT_NE(result.Summary(kTarget).inputs.back().find("empty_table.png: rejected"), std::string::npos);

  // No board anywhere: a clear error naming the files (three different pictures of nothing).
  const std::string message = InputErrorOf([&] {
    CalibrateCamera({{"a.png", blank(cv::Rect(0, 0, 320, 240))},
                     {"b.png", blank(cv::Rect(320, 0, 320, 240))},
                     {"c.png", blank(cv::Rect(640, 0, 320, 240))}},
                    kTarget);
  });
  EXPECT_NE(message.find("found in only 0 of 3"), std::string::npos) << message;
  EXPECT_NE(message.find("a.png, b.png, c.png"), std::string::npos) << message;

  // A view of another size, and a file that is not an image.
  std::vector<NamedImage> mixed = Named();
  mixed.push_back({"small.png", cv::Mat(480, 640, CV_8U, cv::Scalar(0))});
  EXPECT_NE(InputErrorOf([&] { CalibrateCamera(mixed, kTarget); }).find("small.png: is 640×480"), std::string::npos);
  const fs::path not_image = fs::temp_directory_path() / "uphill_vision_calibration_not_image.png";
  { std::ofstream(not_image) << "not a PNG"; }
  EXPECT_NE(InputErrorOf([&] { CalibrateCameraFromFiles({not_image.string()}, kTarget); }).find("cannot be read"),
            std::string::npos);
  fs::remove(not_image);
  // Wrong pattern size: the board is "not found" in any view (and quickly: OpenCV's classic
  // detector took minutes here).
  std::vector<NamedImage> three = Named();
  three.resize(3);
  EXPECT_NE(InputErrorOf([&] { CalibrateCamera(three, ChessboardTarget{8, 6, 0.025}); }).find("found in only 0"),
            std::string::npos);
}

TEST(CameraCalibration, FrontoParallelAndFewViewsGiveAPoorVerdictWithReasons) {
  CameraIntrinsics camera = TrueCamera();  // at half size, to keep the test quick
  camera.width = 640;
  camera.height = 360;
  camera.fx = camera.fy = 500;
  camera.cx = 320;
  camera.cy = 180;
  RandomBoardPoseOptions flat;
  flat.min_tilt_deg = 0;
  flat.max_tilt_deg = 5;
  const ChessboardRenderer renderer(camera, kTarget);
  std::vector<NamedImage> images;
  const auto poses = RandomBoardPoses(camera, kTarget, 6, 7, flat);
  for (size_t i = 0; i < poses.size(); ++i)
    images.push_back({"flat" + std::to_string(i) + ".png", renderer.Render(poses[i]).image});
  const CameraCalibration result = CalibrateCamera(images, kTarget);
  EXPECT_EQ(result.verdict, "poor");
  std::string reasons;
  for (const auto& r : result.reasons) reasons += r + "\n";
  EXPECT_NE(reasons.find("only 6 usable views"), std::string::npos) << reasons;
  EXPECT_NE(reasons.find("nearly parallel to the image"), std::string::npos) << reasons;
}

// ---- scene ----

// A camera beside the apparatus, 1.3 m from the centre line, looking at the middle of the rails
// (the view that films the ball rolling along x); `height` of the camera above the table.
CameraPose LabPose(double height = 0.4) { return LookAtPose({0.6, -1.3, height}, {0.55, 0, 0.12}); }

// The apparatus points of calibration/README.md: O, the rail points at the crossbar
// (L, ±D/2, H), marks on the rails at t = 0.3, 0.6, 0.9 m, and the crossbar's feet (L, ±D/2, 0).
std::vector<Eigen::Vector3d> ApparatusPoints() {
  const double L = 1.165, H = 0.3, D = 0.12;
  std::vector<Eigen::Vector3d> out{{0, 0, 0}, {L, D / 2, H}, {L, -D / 2, H}, {L, D / 2, 0}, {L, -D / 2, 0}};
  for (double t : {0.3, 0.6, 0.9})
    for (double side : {1.0, -1.0}) out.emplace_back(t, side * t * D / (2 * L), t * H / L);
  return out;
}

std::vector<ScenePoint> Observe(const CameraIntrinsics& camera, const CameraPose& pose,
                                const std::vector<Eigen::Vector3d>& positions, double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, noise_px);
  const auto pixels = ProjectApparatusPoints(camera, pose, positions);
  std::vector<ScenePoint> out;
  for (size_t i = 0; i < positions.size(); ++i)
    out.push_back({"row " + std::to_string(i + 2), pixels[i] + Eigen::Vector2d(noise(rng), noise(rng)), positions[i]});
  return out;
}

TEST(SceneCalibration, RecoversTheCameraCentreFromNoisyApparatusPoints) {
  const CameraIntrinsics camera = TrueCamera();
  const CameraPose truth = LabPose();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const SceneCalibrationResult r = CalibrateScene(camera, Observe(camera, truth, ApparatusPoints(), 0.2, seed));
    EXPECT_LT((CameraCentre(r.scene.pose) - CameraCentre(truth)).norm(), 0.006) << "seed " << seed;
    EXPECT_LT(Eigen::AngleAxisd(r.scene.pose.rotation * truth.rotation.transpose()).angle(), 0.2 * kDegree);
    EXPECT_LT(r.rms_px, 0.4);
    EXPECT_GT(r.rms_px, 0.05);  // the noise is there: a fit that ignored the points would not see it
    EXPECT_EQ(r.verdict, "good");
  }
  // Coplanar points (only the rails: they lie in one plane through O) and only 4 of them.
  std::vector<Eigen::Vector3d> rails = ApparatusPoints();
  rails.erase(rails.begin() + 3, rails.begin() + 5);
  const auto coplanar = CalibrateScene(camera, Observe(camera, truth, rails, 0.0, 1));
  EXPECT_LT((CameraCentre(coplanar.scene.pose) - CameraCentre(truth)).norm(), 1e-6);
  rails.resize(4);
  const auto four = CalibrateScene(camera, Observe(camera, truth, rails, 0.0, 1));
  EXPECT_LT((CameraCentre(four.scene.pose) - CameraCentre(truth)).norm(), 1e-6);
  EXPECT_EQ(four.verdict, "poor");  // fewer than 6 points
}

TEST(SceneCalibration, AMisreadPointShowsInTheVerdict) {
  const CameraIntrinsics camera = TrueCamera();
  std::vector<ScenePoint> points = Observe(camera, LabPose(), ApparatusPoints(), 0.2, 3);
  points[6].pixel += Eigen::Vector2d(25, -10);
  const SceneCalibrationResult r = CalibrateScene(camera, points);
  EXPECT_EQ(r.verdict, "poor");
  std::string reasons;
  for (const auto& s : r.reasons) reasons += s + "\n";
  EXPECT_NE(reasons.find("row 8: "), std::string::npos) << reasons;
  EXPECT_EQ(reasons.find("row 7: "), std::string::npos) << reasons;
  EXPECT_EQ(reasons.find("row 9: "), std::string::npos) << reasons;
}

// Issue 11: a wrong row 3 was blamed on row 2, because the misfit pulls the full fit toward
// itself. Whichever row's pixel is misread, that row, and only it, is named: in the verdict, or
// in the refusal when the mistake puts another point behind the camera. (A coordinate mistyped
// by 0.4 m is not yet always traced to its row: 4 of the 9 rows are then only reported as a
// large RMS error or a point behind the camera. Not covered here until it is.)
TEST(SceneCalibration, TheMistypedRowIsTheOneNamed) {
  const CameraIntrinsics camera = TrueCamera();
  for (size_t wrong = 0; wrong < ApparatusPoints().size(); ++wrong) {
    std::vector<ScenePoint> points = Observe(camera, LabPose(), ApparatusPoints(), 0.2, 7);
    points[wrong].pixel += Eigen::Vector2d(-40, 30);  // a misread pixel
    const std::string named = "row " + std::to_string(wrong + 2);
    std::string said;
    try {
      const SceneCalibrationResult r = CalibrateScene(camera, points);
      EXPECT_EQ(r.verdict, "poor") << named;
      for (const auto& reason : r.reasons) said += reason + "\n";
    } catch (const InputError& e) {
      said = e.what();
    }
    EXPECT_NE(said.find(named + ":"), std::string::npos) << said;
    for (size_t other = 0; other < points.size(); ++other)
      if (other != wrong) {
        EXPECT_EQ(said.find("row " + std::to_string(other + 2) + ":"), std::string::npos)
            << "mistake in " << named << ": " << said;
      }
  }
}

// Issue 32: two marks clicked 4-5 px off made the page blame O, the good click, by its residual
// in the full fit. Truth: the pixels are the projections of the apparatus points through a pose
// set here (LabPose, TrueCamera), so the one point moved by 5 px is the only wrong one; the
// leave-one-out check must name it, whichever it is (O included), and the verdict says so.
TEST(SceneCalibration, LeaveOneOutNamesThePointMovedByFivePixels) {
  const CameraIntrinsics camera = TrueCamera();
  for (const double noise_px : {0.0, 0.2})
    for (size_t wrong = 0; wrong < ApparatusPoints().size(); ++wrong) {
      std::vector<ScenePoint> points = Observe(camera, LabPose(), ApparatusPoints(), noise_px, 11);
      points[0].label = "O";
      points[wrong].pixel += Eigen::Vector2d(3, -4);  // 5 px
      const SceneCalibrationResult r = CalibrateScene(camera, points);
      ASSERT_TRUE(r.leave_one_out.has_value());
      EXPECT_EQ(r.leave_one_out->index, wrong) << "noise " << noise_px;
      EXPECT_EQ(r.leave_one_out->label, points[wrong].label);
      EXPECT_TRUE(r.leave_one_out->explains) << points[wrong].label;
      EXPECT_GT(r.leave_one_out->residual_px, 4.0);  // about where the other points put it: 5 px away
      EXPECT_LT(r.leave_one_out->rms_without_px, noise_px + 0.05);
      std::string reasons;
      for (const auto& reason : r.reasons) reasons += reason + "\n";
      EXPECT_NE(reasons.find(points[wrong].label + ": "), std::string::npos) << reasons;
      EXPECT_EQ(r.verdict, "poor");
    }
  // No point moved: the check still reports the largest drop, but nothing is named.
  const SceneCalibrationResult clean = CalibrateScene(camera, Observe(camera, LabPose(), ApparatusPoints(), 0.2, 11));
  ASSERT_TRUE(clean.leave_one_out.has_value());
  EXPECT_FALSE(clean.leave_one_out->explains);
  EXPECT_EQ(clean.verdict, "good");
  // Four points: a pose from the other three would fit them exactly, so there is no check.
  std::vector<Eigen::Vector3d> four = ApparatusPoints();
  four.resize(4);
  EXPECT_FALSE(CalibrateScene(camera, Observe(camera, LabPose(), four, 0.2, 11)).leave_one_out.has_value());
}

TEST(SceneCalibration, DegenerateOrInconsistentPointsAreRefused) {
  const CameraIntrinsics camera = TrueCamera();
  const CameraPose pose = LabPose();
  std::vector<Eigen::Vector3d> one_rail;
  for (double t : {0.1, 0.3, 0.5, 0.7, 0.9}) one_rail.emplace_back(t, t * 0.05, t * 0.25);
  EXPECT_NE(InputErrorOf([&] { CalibrateScene(camera, Observe(camera, pose, one_rail, 0.2, 1)); })
                .find("all lie on one line in the apparatus"),
            std::string::npos);
  const auto three = Observe(camera, pose, {{0, 0, 0}, {1, 0.05, 0.3}, {1, -0.05, 0.3}}, 0, 1);
  EXPECT_NE(InputErrorOf([&] { CalibrateScene(camera, three); }).find("at least 4"), std::string::npos);
  auto outside = Observe(camera, pose, ApparatusPoints(), 0, 1);
  outside[2].pixel = {1500, 200};
  EXPECT_NE(InputErrorOf([&] { CalibrateScene(camera, outside); }).find("row 4: pixel (1500.0, 200.0) is outside"),
            std::string::npos);
  const auto good = Observe(camera, pose, ApparatusPoints(), 0, 1);
  EXPECT_NE(InputErrorOf([&] { CalibrateScene(camera, good, 1920, 1080); }).find("frame: is 1920×1080"),
            std::string::npos);
  auto duplicate = good;
  duplicate[3].position = duplicate[1].position;
  EXPECT_NE(InputErrorOf([&] { CalibrateScene(camera, duplicate); }).find("row 5: has the same position as row 3"),
            std::string::npos);
}

TEST(SceneCalibration, FromAChessboardLaidOnTheTable) {
  const CameraIntrinsics camera = TrueCamera();
  const CameraPose pose = LabPose(0.9);  // looking down at the table
  const ChessboardTarget board{9, 6, 0.03};
  // The board face up on the table, its first inner corner at (0.35, 0.05, 0), its rows of
  // corners along x; read on the sheet its columns run "down", here along −y.
  const Eigen::Vector3d origin(0.35, 0.05, 0), x_axis = Eigen::Vector3d::UnitX(), y_axis = -Eigen::Vector3d::UnitY();
  Eigen::Matrix3d board_to_apparatus;
  board_to_apparatus << x_axis, y_axis, x_axis.cross(y_axis);
  CameraPose board_pose;
  board_pose.rotation = pose.rotation * board_to_apparatus;
  board_pose.translation = pose.rotation * origin + pose.translation;
  ChessboardRenderOptions options;
  options.supersampling = 3;
  options.noise_sigma = 1;
  const ChessboardView view = ChessboardRenderer(camera, board).Render(board_pose, options);
  const cv::Mat& image = view.image;
  const std::vector<Eigen::Vector2d> found = FindChessboardCorners(image, board);
  ASSERT_EQ(found.size(), 54u);
  EXPECT_LT((found.front() - view.corners.front()).norm(), 0.5);  // the origin is told apart
  const SceneCalibrationResult r =
      CalibrateSceneFromChessboard(camera, {"table.png", image}, board, origin, x_axis, y_axis);
  EXPECT_LT((CameraCentre(r.scene.pose) - CameraCentre(pose)).norm(), 0.005);
  EXPECT_LT(r.rms_px, 0.3);
  EXPECT_NE(InputErrorOf([&] {
              CalibrateSceneFromChessboard(camera, {"blank.png", cv::Mat(720, 1280, CV_8U, cv::Scalar(200))}, board,
                                           origin, x_axis, y_axis);
            }).find("blank.png: the 9×6 inner corners"),
            std::string::npos);
}

TEST(ChessboardTarget, PrintableImageHasTheSquaresAndMargin) {
  const cv::Mat image = ChessboardTargetImage(kTarget, 10);
  EXPECT_EQ(image.cols, (9 + 1 + 2) * 10);
  EXPECT_EQ(image.rows, (6 + 1 + 2) * 10);
  EXPECT_EQ(image.at<uchar>(5, 5), 255);    // margin
  EXPECT_EQ(image.at<uchar>(15, 15), 0);    // first square: black
  EXPECT_EQ(image.at<uchar>(15, 25), 255);  // second square: white
  EXPECT_EQ(FindChessboardCorners(image, kTarget).size(), 54u);
}

// ---- the command line: `uphill calibrate` ----

using testing::RunUphill;

// A new folder of its own for each test. ctest runs each test of this file as its own process,
// in parallel with the other tests and with the same tests of other builds (release and
// sanitize, other checkouts) on the machine: a folder shared by name was emptied by one test's
// final remove_all while another was still writing views into it or reading cam.json from it.
fs::path CliDir() {
  std::string pattern = (fs::temp_directory_path() / "uphill_vision_calibration_cli_XXXXXX").string();
  if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed in " + fs::temp_directory_path().string());
  return pattern;
}

TEST_F(CameraCalibrationTest, CommandLineCalibratesCameraAndScene) {
  const fs::path dir = CliDir();
  std::string images;
  for (const auto& view : Named()) {
    cv::imwrite((dir / view.name).string(), view.image);
    images += " " + (dir / view.name).string();
  }
  const std::string cam = (dir / "cam.json").string();
  const auto camera = RunUphill("calibrate camera" + images + " --cols 9 --rows 6 --square 25mm -o " + cam);
  ASSERT_EQ(camera.status, 0) << camera.err;
  EXPECT_NE(camera.out.find("RMS reprojection error"), std::string::npos);
  EXPECT_NE(camera.out.find("verdict: good"), std::string::npos);
  const CameraIntrinsics read = ReadCameraFile(cam);
  EXPECT_NEAR(read.fx / TrueCamera().fx, 1, 0.005);

  // Scene points from the true pose, read back through the CSV (mm in the header) and the file.
  const auto positions = ApparatusPoints();
  const auto pixels = ProjectApparatusPoints(TrueCamera(), LabPose(), positions);
  std::ostringstream csv;
  csv << "name,u,v,x_mm,y_mm,z_mm\n";
  csv.precision(10);
  for (size_t i = 0; i < positions.size(); ++i)
    csv << "P" << i << "," << pixels[i].x() << "," << pixels[i].y() << "," << positions[i].x() * 1000 << ","
        << positions[i].y() * 1000 << "," << positions[i].z() * 1000 << "\n";
  const fs::path points = dir / "points.csv";
  { std::ofstream(points) << csv.str(); }
  const std::string scene_path = (dir / "scene.json").string();
  const auto scene = RunUphill("calibrate scene --camera " + cam + " --points " + points.string() + " -o " + scene_path);
  ASSERT_EQ(scene.status, 0) << scene.err;
  EXPECT_NE(scene.out.find("camera centre (apparatus frame)"), std::string::npos);
  const SceneCalibration read_scene = ReadSceneFile(scene_path);
  // The calibrated (not the true) intrinsics: the centre is still within a few mm.
  EXPECT_LT((CameraCentre(read_scene.pose) - CameraCentre(LabPose())).norm(), 0.005);
  // The scene file keeps the points as given (issue 32), named by their `name` cells.
  const SceneInputs kept = ReadSceneInputs(scene_path);
  ASSERT_EQ(kept.points.size(), positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    EXPECT_EQ(kept.points[i].label, "P" + std::to_string(i));
    EXPECT_LT((kept.points[i].pixel - pixels[i]).norm(), 1e-6);  // 10 digits in the CSV
    EXPECT_LT((kept.points[i].position - positions[i]).norm(), 1e-9);
  }
  // One pixel moved by 5 px: the leave-one-out line names its row (row 5: P3).
  std::string moved = csv.str();
  const size_t row5 = moved.find("\nP3,") + 4;
  moved.replace(row5, moved.find(',', row5) - row5, std::to_string(pixels[3].x() + 5));
  { std::ofstream(dir / "moved.csv") << moved; }
  const auto loo = RunUphill("calibrate scene --camera " + cam + " --points " + (dir / "moved.csv").string() + " -o " +
                             (dir / "moved.json").string());
  ASSERT_EQ(loo.status, 0) << loo.err;
  EXPECT_NE(loo.out.find("leave-one-out: without " + (dir / "moved.csv").string() + ", row 5 (P3)"), std::string::npos)
      << loo.out;
  EXPECT_NE(loo.out.find("check this point"), std::string::npos) << loo.out;

  // Bad input: exit 2, the message names file, row and column, or the flag.
  const std::string refused_output = (dir / "x.json").string();
  { std::ofstream(dir / "bad.csv") << "u,v,x_mm,y_mm,z_mm\n1,2,0,0,0\n3,4,abc,0,0\n"; }
  auto bad = RunUphill("calibrate scene --camera " + cam + " --points " + (dir / "bad.csv").string() + " -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("bad.csv, row 3, column x_mm: 'abc' is not a number"), std::string::npos) << bad.err;
  { std::ofstream(dir / "nounit.csv") << "u,v,x,y,z\n1,2,0,0,0\n"; }
  bad = RunUphill("calibrate scene --camera " + cam + " --points " + (dir / "nounit.csv").string() + " -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("nounit.csv, row 2, column x: '0' has no unit"), std::string::npos) << bad.err;
  { std::ofstream(dir / "line.csv") << "u,v,x_mm,y_mm,z_mm\n100,100,0,0,0\n200,200,100,0,0\n300,300,200,0,0\n400,400,300,0,0\n"; }
  bad = RunUphill("calibrate scene --camera " + cam + " --points " + (dir / "line.csv").string() + " -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("line.csv: points: all lie on one line"), std::string::npos) << bad.err;
  cv::imwrite((dir / "small_frame.png").string(), cv::Mat(480, 640, CV_8U, cv::Scalar(0)));
  bad = RunUphill("calibrate scene --camera " + cam + " --points " + points.string() + " --frame " +
                  (dir / "small_frame.png").string() + " -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("small_frame.png: is 640×480 pixels but the camera was calibrated at 1280×720"),
            std::string::npos) << bad.err;
  bad = RunUphill("calibrate camera " + points.string() + " --cols 9 --rows 6 --square 25mm -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("points.csv: cannot be read as an image"), std::string::npos) << bad.err;
  bad = RunUphill("calibrate camera" + images + " --cols 9 --rows 6 --square 25 -o " + refused_output);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--square: '25' has no unit"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(refused_output));  // no output for refused input
  fs::remove_all(dir);
}

// calibration/views: the sample camera's chessboard views (calibration/README.md). Truth: the
// camera that rendered them, make_video's 640 × 360 camera with fx = fy = 650 px (cam.json of
// scripts/make-sample-videos.sh); the verdict must be "good".
TEST(CameraCalibration, TheShippedSampleViewsGiveAGoodVerdict) {
  std::vector<std::string> views;
  for (const auto& entry : fs::directory_iterator(fs::path(UPHILL_SOURCE_DIR) / "calibration" / "views"))
    views.push_back(entry.path().string());
  ASSERT_GE(views.size(), 15u);
  const CameraCalibration c = CalibrateCameraFromFiles(views, ChessboardTarget{9, 6, 0.020});
  EXPECT_EQ(c.verdict, "good") << (c.reasons.empty() ? "" : c.reasons.front());
  EXPECT_NEAR(c.camera.fx / 650, 1, 0.005);
  EXPECT_NEAR(c.camera.fy / 650, 1, 0.005);
}

TEST(CalibrateTargetCommand, WritesAnSvgOfExactSizeAndAPngThatIsDetected) {
  const fs::path dir = CliDir();
  const auto svg = RunUphill("calibrate target --cols 9 --rows 6 --square 20mm -o " + (dir / "board.svg").string());
  ASSERT_EQ(svg.status, 0) << svg.err;
  std::ifstream in(dir / "board.svg");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("width=\"240mm\" height=\"180mm\""), std::string::npos);  // (10 + 2) × 20, (7 + 2) × 20
  const auto png = RunUphill("calibrate target --cols 9 --rows 6 --square 20mm --dpi 127 -o " +
                             (dir / "board.png").string());
  ASSERT_EQ(png.status, 0) << png.err;
  const cv::Mat image = cv::imread((dir / "board.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(image.cols, 12 * 100);  // 20 mm at 127 dpi = 100 px
  EXPECT_EQ(FindChessboardCorners(image, kTarget).size(), 54u);
  const auto bad = RunUphill("calibrate target --cols 1 --square 20mm -o " + (dir / "b.svg").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--cols: must be 2 to 100"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// ---- the pixel limit and the ranges (vision/decode_limits.hpp, "ranges" in calibration.hpp) ----

// ImageHeaderSize reads the size OpenCV's own encoders wrote (a round trip), for each format whose
// size is checked before decoding; the limit is the documented one (docs/calibrate.md): a 4K frame
// and a 50-megapixel photo pass, 8000 × 8000 and 20,000 × 20,000 do not.
TEST(DecodeLimits, HeaderSizesAreThoseTheEncodersWroteAndTheLimitIsTheDocumentedOne) {
  const fs::path dir = CliDir();
  for (const std::string ext : {".png", ".jpg", ".bmp", ".tif"}) {
    const std::string path = (dir / ("view" + ext)).string();
    ASSERT_TRUE(cv::imwrite(path, cv::Mat(23, 37, CV_8UC3, cv::Scalar(10, 20, 30))));
    const std::optional<PixelSize> size = ImageHeaderSize(path);
    ASSERT_TRUE(size) << ext;
    EXPECT_EQ(size->width, 37) << ext;
    EXPECT_EQ(size->height, 23) << ext;
  }
  { std::ofstream(dir / "text.png") << "not an image at all"; }
  EXPECT_FALSE(ImageHeaderSize((dir / "text.png").string()));
  EXPECT_FALSE(ImageHeaderSize((dir / "absent.png").string()));
  EXPECT_NO_THROW(CheckPixelCount(3840, 2160, "uhd.mp4", "a video with frames"));
  EXPECT_NO_THROW(CheckPixelCount(8688, 5792, "photo.jpg", "an image"));
  EXPECT_THROW(CheckPixelCount(8000, 8000, "big.avi", "a video with frames"), InputError);
  EXPECT_THROW(CheckPixelCount(20000, 20000, "huge.png", "an image"), InputError);
  EXPECT_THROW(CheckPixelCount(std::int64_t{1} << 40, std::int64_t{1} << 40, "overflow.png", "an image"), InputError);
  fs::remove_all(dir);
}

// Guards: `calibrate camera` decoded a PNG declaring 20,000 × 20,000 pixels (13 such views took
// 5.2 GB). Truth: the limit of docs/calibrate.md, checked on the header: exit 2, the file named.
TEST(CalibrateCommandLimits, AnImageOverThePixelLimitExitsTwoBeforeDecoding) {
  const fs::path dir = CliDir();
  const fs::path huge = dir / "huge.png";
  { std::ofstream(huge, std::ios::binary) << PngDeclaring(20000, 20000); }
  const auto r = RunUphill("calibrate camera " + huge.string() + " --cols 9 --rows 6 --square 20mm -o " +
                           (dir / "cam.json").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("huge.png: an image of 20000 × 20000 pixels is more than uphill decodes: at most 60 million "
                       "pixels"),
            std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "cam.json"));
  fs::remove_all(dir);
}

// Guards: `calibrate camera --square 1e50mm` (and 1e308, 1e-50, 1e-300 mm) and `calibrate scene`
// with the points' coordinates times 1e80 ended in OpenCV assertions (exit 1). Truth: the ranges of
// docs/calibrate.md (a square 0.1 mm to 1 m, a coordinate within ±100 m of O): exit 2, one line
// naming the flag or the point, the value with its unit and the range (docs/exit-codes.md).
TEST_F(CameraCalibrationTest, OutOfRangeSquaresAndPointsExitTwoNamingTheRange) {
  const fs::path dir = CliDir();
  std::string images;  // views in which the board is found: the square reaches calibrateCamera
  for (const auto& view : Named()) {
    cv::imwrite((dir / view.name).string(), view.image);
    images += " " + (dir / view.name).string();
  }
  for (const std::string square : {"1e50mm", "1e308mm", "1e-50mm", "1e-300mm"}) {
    const auto r = RunUphill("calibrate camera" + images + " --cols 9 --rows 6 --square " + square + " -o " +
                             (dir / "cam.json").string());
    EXPECT_EQ(r.status, 2) << square << ": " << r.err;
    EXPECT_NE(r.err.find("--square: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" mm is outside the allowed range 0.1 mm to 1000 mm"), std::string::npos) << r.err;
  }
  const std::string cam = (dir / "cam.json").string();
  WriteCameraFile(cam, TrueCamera(), CalibrationSummary{});
  const auto positions = ApparatusPoints();
  const auto pixels = ProjectApparatusPoints(TrueCamera(), LabPose(), positions);
  std::ostringstream csv;
  csv << "name,u,v,x_mm,y_mm,z_mm\n";
  for (size_t i = 0; i < positions.size(); ++i)
    csv << "P" << i << "," << pixels[i].x() << "," << pixels[i].y() << "," << positions[i].x() * 1e83 << ","
        << positions[i].y() * 1e83 << "," << positions[i].z() * 1e83 << "\n";
  { std::ofstream(dir / "far.csv") << csv.str(); }
  const auto r = RunUphill("calibrate scene --camera " + cam + " --points " + (dir / "far.csv").string() + " -o " +
                           (dir / "scene.json").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(" mm is outside the allowed range -100000 mm to 100000 mm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "scene.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
