// The camera model (src/vision/camera.hpp): projection against a hand computation, the
// undistortion round trip, the camera and scene files (round trip and refusals).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/calib3d.hpp>
#include <random>

#include "model/input_error.hpp"
#include "vision/camera.hpp"
#include "vision_test_support.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

CameraIntrinsics Camera1280(std::vector<double> distortion) {
  return {1280, 720, 1000, 1002, 641.5, 358.25, std::move(distortion)};
}

// A camera 1.2 m behind and 0.45 m above O, looking down the rails.
CameraPose LabPose() { return LookAtPose({-0.6, 0.05, 0.5}, {0.5, 0, 0.1}); }

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("uphill_vision_camera_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }
std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}


TEST(CameraModel, ProjectsWithoutDistortionAsThePinholeFormula) {
  const CameraIntrinsics c = Camera1280({});
  // (0.1, −0.05, 2) m: u = fx·x/z + cx = 1000·0.05 + 641.5 = 691.5, v = 1002·(−0.025) + 358.25 = 333.2
  const Eigen::Vector2d p = ProjectCameraPoint(c, {0.1, -0.05, 2.0});
  EXPECT_NEAR(p.x(), 691.5, 1e-9);
  EXPECT_NEAR(p.y(), 333.2, 1e-9);
  const Eigen::Vector2d n = UndistortPixel(c, p);
  EXPECT_NEAR(n.x(), 0.05, 1e-12);
  EXPECT_NEAR(n.y(), -0.025, 1e-12);
}

TEST(CameraModel, ProjectsWithRadialDistortionAsOpenCVsFormula) {
  // k1 = −0.1, k2 = 0.02 at (x, y) = (0.3, 0.2): r² = 0.13, factor 1 − 0.013 + 0.02·0.0169
  const CameraIntrinsics c = Camera1280({-0.1, 0.02, 0, 0, 0});
  const double factor = 1 - 0.1 * 0.13 + 0.02 * 0.13 * 0.13;
  const Eigen::Vector2d p = ProjectCameraPoint(c, {0.3, 0.2, 1.0});
  EXPECT_NEAR(p.x(), 1000 * 0.3 * factor + 641.5, 1e-9);
  EXPECT_NEAR(p.y(), 1002 * 0.2 * factor + 358.25, 1e-9);
}

// Truth: cv::projectPoints itself. Single points are projected by uphill's own arithmetic for the
// plain lens models (4, 5 and 8 coefficients); the thin prism (12) goes through OpenCV. Strong
// coefficients, tangential ones included, over points that fill a wide view.
TEST(CameraModel, ProjectionAgreesWithOpenCVForEveryCoefficientCount) {
  const std::vector<std::vector<double>> models = {
      {},
      {-0.28, 0.11, 0.0012, -0.0009},
      {-0.28, 0.11, 0.0012, -0.0009, -0.03},
      {0.9, -0.4, 0.0012, -0.0009, 0.05, 1.1, -0.2, 0.07},
      {-0.28, 0.11, 0.0012, -0.0009, -0.03, 0, 0, 0, 0.001, -0.002, 0.0015, 0.0005}};
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> lateral(-0.6, 0.6), depth(0.5, 3.0);
  for (const std::vector<double>& d : models) {
    const CameraIntrinsics c = Camera1280(d);
    std::vector<cv::Point3d> object;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 200; ++i) {
      const double z = depth(random);
      points.emplace_back(lateral(random) * z, lateral(random) * z * 0.6, z);
      object.emplace_back(points.back().x(), points.back().y(), z);
    }
    std::vector<cv::Point2d> expected;
    const cv::Matx33d k(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, d.empty() ? cv::Mat() : cv::Mat(d), expected);
    const std::vector<Eigen::Vector2d> many = ProjectApparatusPoints(c, CameraPose{}, points);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector2d one = ProjectCameraPoint(c, points[i]);
      const double tolerance = 1e-9 * (1 + std::abs(expected[i].x) + std::abs(expected[i].y));
      EXPECT_NEAR(one.x(), expected[i].x, tolerance) << d.size() << " coefficients, point " << i;
      EXPECT_NEAR(one.y(), expected[i].y, tolerance) << d.size() << " coefficients, point " << i;
      EXPECT_EQ(one, many[i]);
    }
  }
}

TEST(CameraModel, UndistortionRoundTripIsBelowAMicroPixelOverTheWholeImage) {
  for (const auto& distortion : std::vector<std::vector<double>>{
           {}, {-0.1, 0.0, 0, 0}, {-0.3, 0.12, 0.001, -0.0015, -0.02}, {0.15, -0.05, 0, 0, 0.01}}) {
    const CameraIntrinsics c = Camera1280(distortion);
    std::vector<Eigen::Vector2d> pixels;
    for (double u = 0; u <= c.width - 1; u += (c.width - 1) / 16.0)
      for (double v = 0; v <= c.height - 1; v += (c.height - 1) / 9.0) pixels.emplace_back(u, v);
    const std::vector<Eigen::Vector2d> rays = UndistortPixels(c, pixels);
    double worst = 0;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const Eigen::Vector2d back = ProjectCameraPoint(c, {rays[i].x(), rays[i].y(), 1.0});
      worst = std::max(worst, (back - pixels[i]).norm());
      // The single-point form agrees with the batch form.
      if (i % 37 == 0) {
        EXPECT_LT((UndistortPixel(c, pixels[i]) - rays[i]).norm(), 1e-15);
      }
    }
    EXPECT_LT(worst, 1e-6) << "distortion with " << distortion.size() << " coefficients";
  }
}

TEST(CameraModel, ApparatusPointsProjectThroughThePose) {
  const CameraIntrinsics c = Camera1280({-0.1, 0.01, 0, 0, 0});
  const CameraPose pose = LabPose();
  EXPECT_LT((CameraCentre(pose) - Eigen::Vector3d(-0.6, 0.05, 0.5)).norm(), 1e-12);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(0, 1), y(-0.1, 0.1), z(0, 0.3);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  const auto pixels = ProjectApparatusPoints(c, pose, points);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT((ProjectApparatusPoint(c, pose, points[i]) - pixels[i]).norm(), 1e-12);
    // The viewing ray of the pixel passes through the point.
    const Eigen::Vector2d n = UndistortPixel(c, pixels[i]);
    const Eigen::Vector3d ray = pose.rotation.transpose() * Eigen::Vector3d(n.x(), n.y(), 1).normalized();
    const Eigen::Vector3d to_point = points[i] - CameraCentre(pose);
    EXPECT_LT(to_point.cross(ray).norm(), 1e-9);  // distance of the point from the ray, metres
  }
}

TEST(CameraModel, LookAtPoseLooksAtTheTargetWithUpUpward) {
  const CameraIntrinsics c = Camera1280({});
  const CameraPose pose = LookAtPose({0.6, -1.3, 0.4}, {0.55, 0, 0.12});
  EXPECT_LT((pose.rotation * pose.rotation.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(pose.rotation.determinant(), 1, 1e-14);
  // The target is on the optical axis: at the principal point.
  EXPECT_LT((ProjectApparatusPoint(c, pose, {0.55, 0, 0.12}) - Eigen::Vector2d(c.cx, c.cy)).norm(), 1e-9);
  // A point above the target is higher in the image (smaller v), +x is to the right from −y.
  EXPECT_LT(ProjectApparatusPoint(c, pose, {0.55, 0, 0.2}).y(), c.cy - 10);
  EXPECT_GT(ProjectApparatusPoint(c, pose, {0.65, 0, 0.12}).x(), c.cx + 10);
  EXPECT_NE(InputErrorOf([] { LookAtPose({0, 0, 1}, {0, 0, 0}); }).find("parallel"), std::string::npos);
  EXPECT_NE(InputErrorOf([] { LookAtPose({0, 0, 1}, {0, 0, 1}); }).find("differ"), std::string::npos);
}

// Truth: the closed form. With k1 < 0 alone the radial mapping r + k1·r³ stops growing where its
// derivative 1 + 3·k1·r² vanishes, r = sqrt(−1/(3·k1)); beyond, a point projects back toward the
// centre of the picture (the fold the tracker must not draw a rail through).
TEST(CameraModel, LensModelReachIsWhereTheRadialMappingStopsGrowing) {
  EXPECT_TRUE(std::isinf(LensModelReach(Camera1280({}))));
  EXPECT_TRUE(std::isinf(LensModelReach(Camera1280({-0.12, 0.06, 0, 0, 0}))));  // 1 − 0.36r² + 0.3r⁴ > 0
  const CameraIntrinsics barrel = Camera1280({-0.12, 0, 0, 0, 0});
  const double reach = LensModelReach(barrel);
  EXPECT_NEAR(reach, std::sqrt(1 / 0.36), 1e-3);  // 1.667, the step of the search
  // The ray-traced footage's lens (k3 < 0) folds too: a point at 1.3× the reach lands nearer the
  // centre than one at the reach.
  const CameraIntrinsics footage{1920, 1080, 1728, 1728, 971.02, 531.82, {-0.12, 0.06, 0.0007, -0.0004, -0.015}};
  const double folds = LensModelReach(footage);
  ASSERT_TRUE(std::isfinite(folds));
  const Eigen::Vector2d centre(footage.cx, footage.cy);
  const double at_reach = (ProjectCameraPoint(footage, {folds, 0, 1}) - centre).norm();
  const double beyond = (ProjectCameraPoint(footage, {1.3 * folds, 0, 1}) - centre).norm();
  EXPECT_LT(beyond, at_reach);
  std::printf("  reach: barrel %.3f, the footage's lens %.3f (%.0f px from the centre at most)\n", reach, folds,
              at_reach);
}

TEST(CameraModel, PointsBehindTheCameraAreRefused) {
  const CameraIntrinsics c = Camera1280({});
  EXPECT_NE(InputErrorOf([&] { ProjectCameraPoint(c, {0, 0, -1}); }).find("in front of the camera"),
            std::string::npos);
  EXPECT_NE(InputErrorOf([&] { ProjectCameraPoint(c, {0, 0, 0}); }), "");
  EXPECT_NE(InputErrorOf([&] { ProjectCameraPoint(c, {NAN, 0, 1}); }), "");
}

TEST(CameraFiles, CameraAndSceneRoundTripExactly) {
  const fs::path dir = TempDir("round_trip");
  const CameraIntrinsics c = Camera1280({-0.1234567890123, 0.01, 1e-4, -2e-4, 0.003});
  CalibrationSummary summary;
  summary.method = "test";
  summary.rms_px = 0.2;
  summary.verdict = "good";
  WriteCameraFile((dir / "cam.json").string(), c, summary);
  const CameraIntrinsics r = ReadCameraFile((dir / "cam.json").string());
  EXPECT_EQ(r.width, c.width);
  EXPECT_EQ(r.height, c.height);
  EXPECT_EQ(r.fx, c.fx);
  EXPECT_EQ(r.fy, c.fy);
  EXPECT_EQ(r.cx, c.cx);
  EXPECT_EQ(r.cy, c.cy);
  EXPECT_EQ(r.distortion, c.distortion);

  SceneCalibration scene{c, LabPose()};
  WriteSceneFile((dir / "scene.json").string(), scene, summary);
  const SceneCalibration s = ReadSceneFile((dir / "scene.json").string());
  EXPECT_EQ(s.camera.fx, c.fx);
  EXPECT_EQ(s.camera.distortion, c.distortion);
  EXPECT_EQ(s.pose.rotation, scene.pose.rotation);
  EXPECT_EQ(s.pose.translation, scene.pose.translation);
  fs::remove_all(dir);
}

// Issue 32: the scene file keeps what its pose was solved from (the clicks with their names, the
// marks, the table's height). Truth: a round trip, write then read, gives back exactly what was
// written; a file without them (as written before they were kept) reads as none.
TEST(CameraFiles, SceneInputsRoundTripExactly) {
  const fs::path dir = TempDir("scene_inputs");
  const SceneCalibration scene{Camera1280({-0.1, 0.01, 0, 0}), LabPose()};
  SceneInputs inputs;
  inputs.points = {{"O", {640.25, 512.125}, {0, 0, 0}},
                   {"left rail at the crossbar", {1001.5, 200.75}, {1.165, 0.06, 0.3}},
                   {"mark 1 (left)", {812.0 / 3, 300.1}, {0.3, 0.0154506437768, 0.0772532188841}}};
  inputs.marks_x = {0.3, 0.6};
  inputs.table_z = -0.0125;
  const std::string path = (dir / "scene-main.json").string();
  WriteSceneFile(path, scene, CalibrationSummary{}, inputs);
  const SceneInputs read = ReadSceneInputs(path);
  ASSERT_EQ(read.points.size(), inputs.points.size());
  for (size_t i = 0; i < inputs.points.size(); ++i) {
    EXPECT_EQ(read.points[i].label, inputs.points[i].label);
    EXPECT_EQ(read.points[i].pixel, inputs.points[i].pixel);
    EXPECT_EQ(read.points[i].position, inputs.points[i].position);
  }
  EXPECT_EQ(read.marks_x, inputs.marks_x);
  EXPECT_EQ(read.table_z, inputs.table_z);
  EXPECT_EQ(ReadSceneFile(path).pose.translation, scene.pose.translation);  // the pose as before

  const std::string old_path = (dir / "scene-old.json").string();
  WriteSceneFile(old_path, scene, CalibrationSummary{});
  const std::string old_text = ReadText(old_path);
  EXPECT_EQ(old_text.find("points"), std::string::npos);  // nothing written that was not given
  const SceneInputs none = ParseSceneInputs(old_path, old_text);
  EXPECT_TRUE(none.points.empty());
  EXPECT_TRUE(none.marks_x.empty());
  EXPECT_FALSE(none.table_z.has_value());
  EXPECT_EQ(ParseSceneFile(old_path, old_text).pose.rotation, scene.pose.rotation);

  // A malformed record is refused naming the key, by both readers; a NaN is refused on writing.
  std::string text = ReadText(path);
  text.replace(text.find("\"u_px\""), 6, "\"u_mm\"");
  EXPECT_NE(InputErrorOf([&] { ParseSceneFile(path, text); }).find(path + ".points[0].u_mm: unit does not match"),
            std::string::npos);
  EXPECT_NE(InputErrorOf([&] { ParseSceneInputs(path, text); }).find(".points[0].u_mm"), std::string::npos);
  inputs.points[1].pixel.x() = NAN;
  EXPECT_NE(InputErrorOf([&] { SceneFileText(scene, {}, inputs); }).find("left rail at the crossbar"),
            std::string::npos);
  fs::remove_all(dir);
}

TEST(CameraFiles, BadFilesAreRefusedNamingFileKeyAndRule) {
  const fs::path dir = TempDir("bad");
  const std::string good_intrinsics =
      R"("image_width_px": 1280, "image_height_px": 720, "fx_px": 1000, "fy_px": 1000,
         "cx_px": 640, "cy_px": 360, "distortion": [-0.1, 0, 0, 0])";
  struct Case {
    std::string content, expected;
  };
  const std::vector<Case> cases = {
      {"{", "is not valid JSON"},
      {R"({"format": "uphill-scene/1", )" + good_intrinsics + "}", "format: must be \"uphill-camera/1\""},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280})", "image_height_px: is missing"},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280, "image_height_px": 720, "fx_px": -5,
          "fy_px": 1000, "cx_px": 640, "cy_px": 360})", "fx: must be > 0"},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280.5, "image_height_px": 720, "fx_px": 1,
          "fy_px": 1000, "cx_px": 640, "cy_px": 360})", "image_width_px: must be a positive whole number"},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280, "image_height_px": 720, "fx_mm": 5,
          "fy_px": 1000, "cx_px": 640, "cy_px": 360})", "fx_mm: unit does not match"},
      {R"({"format": "uphill-camera/1", "colour": 1, )" + good_intrinsics + "}", "colour: unknown key"},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280, "image_height_px": 720, "fx_px": 1000,
          "fy_px": 1000, "cx_px": "640", "cy_px": 360})", "cx_px: must be a number"},
      {R"({"format": "uphill-camera/1", "image_width_px": 1280, "image_height_px": 720, "fx_px": 1000,
          "fy_px": 1000, "cx_px": 640, "cy_px": 360, "distortion": [0.1, 0.2]})",
       "must hold 0, 4, 5 or 8 coefficients"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path = (dir / ("cam" + std::to_string(i) + ".json")).string();
    WriteText(path, cases[i].content);
    const std::string message = InputErrorOf([&] { ReadCameraFile(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(cases[i].expected), std::string::npos) << "case " << i << ": " << message;
  }
  EXPECT_NE(InputErrorOf([&] { ReadCameraFile((dir / "absent.json").string()); }).find("cannot be opened"),
            std::string::npos);

  const std::string scene_head = R"({"format": "uphill-scene/1", "camera": {)" + good_intrinsics + "}, ";
  const std::vector<Case> scene_cases = {
      {scene_head + R"("pose": {"rotation": [[1,0,0],[0,1,0],[0,0,1.1]], "translation_m": [0,0,1]}})",
       "rotation: is not orthonormal"},
      {scene_head + R"("pose": {"rotation": [[1,0,0],[0,1,0],[0,0,-1]], "translation_m": [0,0,1]}})",
       "rotation: is a reflection"},
      {scene_head + R"("pose": {"rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation_mm": [0,0,1]}})",
       "translation_mm: unit does not match"},
      {scene_head + R"("pose": {"rotation": [[1,0,0],[0,1,0]], "translation_m": [0,0,1]}})",
       "rotation: must be 3 rows of 3 numbers"},
      {scene_head + R"("pose": {"rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation_m": [0,0,1]},
          "camera_centre_m": [0, 0, 1]})",
       "camera_centre_m: does not match the pose"},
      {R"({"format": "uphill-scene/1", "pose": {}})", "camera: is missing"},
  };
  for (size_t i = 0; i < scene_cases.size(); ++i) {
    const std::string path = (dir / ("scene" + std::to_string(i) + ".json")).string();
    WriteText(path, scene_cases[i].content);
    const std::string message = InputErrorOf([&] { ReadSceneFile(path); });
    EXPECT_NE(message.find(scene_cases[i].expected), std::string::npos) << "case " << i << ": " << message;
  }
  // A camera without distortion is valid; a writer refuses invalid intrinsics before writing.
  const std::string path = (dir / "plain.json").string();
  WriteText(path, R"({"format": "uphill-camera/1", "image_width_px": 640, "image_height_px": 480,
                      "fx_px": 500, "fy_px": 500, "cx_px": 320, "cy_px": 240})");
  EXPECT_TRUE(ReadCameraFile(path).distortion.empty());
  CameraIntrinsics bad = Camera1280({});
  bad.fy = 0;
  EXPECT_NE(InputErrorOf([&] { WriteCameraFile((dir / "never.json").string(), bad, {}); }), "");
  EXPECT_FALSE(fs::exists(dir / "never.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
