// The POV-Ray footage generator (src/footage/footage_clip.hpp): its geometry against OpenCV, and
// the user's whole path (calibrate camera -> calibrate scene -> track) on a small rendered clip.
//
// Where the truth comes from: POV-Ray, an independent ray tracer, renders points of known
// position; cv::projectPoints says where the OpenCV camera model puts them. The footage's ground
// truth is cv::projectPoints of the body's centre, so it is as good as the agreement measured here.
// The tracking test compares the current tracker against that truth; its bounds state what the
// tracker does today on this clip (a grey-level ball on wood: where it is good).
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "io/csv_table.hpp"
#include "motion/motion.hpp"
#include "footage/footage_clip.hpp"
#include "footage/footage_conditions.hpp"
#include "footage/lens_remap.hpp"
#include "footage/povray_render.hpp"
#include "footage/povray_scene.hpp"
#include "footage/sensor_model.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2d;
using Eigen::Vector3d;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("uphill-povray-test-" + name + "-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Points spread over the whole frame of `cal` (corners included), `depth` metres in front.
std::vector<Vector3d> GridPoints(const SceneCalibration& cal, double depth) {
  std::vector<Vector3d> points;
  const CameraIntrinsics& k = cal.camera;
  for (double fu : {0.06, 0.3, 0.55, 0.8, 0.94})
    for (double fv : {0.08, 0.5, 0.92}) {
      // The ray of the raw pixel, at `depth` along the optical axis, in the apparatus frame.
      const Vector2d n = UndistortPixel(k, Vector2d(fu * (k.width - 1), fv * (k.height - 1)));
      const Vector3d cam(n.x() * depth, n.y() * depth, depth);
      points.push_back(cal.pose.rotation.transpose() * (cam - cal.pose.translation));
    }
  return points;
}

// Intensity-weighted centroid of the blob nearest `guess` (window of ±radius px).
Vector2d Centroid(const cv::Mat& grey, const Vector2d& guess, int radius) {
  double s = 0, su = 0, sv = 0;
  const int u0 = static_cast<int>(std::lround(guess.x())), v0 = static_cast<int>(std::lround(guess.y()));
  for (int v = std::max(0, v0 - radius); v <= std::min(grey.rows - 1, v0 + radius); ++v)
    for (int u = std::max(0, u0 - radius); u <= std::min(grey.cols - 1, u0 + radius); ++u) {
      const double w = grey.at<float>(v, u);
      s += w, su += w * u, sv += w * v;
    }
  return s > 0 ? Vector2d(su / s, sv / s) : Vector2d(NAN, NAN);
}

// A scene of glowing spheres (uniform emission, no lights) on black: each one's picture is its
// silhouette, filled evenly.
std::string GlowingSpheres(const PovrayShot& shot, const std::vector<Vector3d>& centres, double radius) {
  std::ostringstream out;
  out << "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb 0 }\n" << PovrayCameraText(shot);
  char line[200];
  for (const Vector3d& c : centres) {
    std::snprintf(line, sizeof line,
                  "sphere { <%.9g, %.9g, %.9g>, %.9g pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }\n",
                  c.x() * 1e3, c.y() * 1e3, c.z() * 1e3, radius * 1e3);
    out << line;
  }
  return out.str();
}

// Where OpenCV's camera model puts the centre of a sphere's silhouette: the points where the
// cone of rays from the camera touches the sphere, projected with cv::projectPoints (distortion
// included), and the centre of the ellipse through them (cv::fitEllipse; exact for a pinhole,
// within ~1e-3 px of the centroid for the distortion of a sphere a few pixels wide). Not the
// projection of the sphere's centre: perspective moves the silhouette outward by
// (radius/distance)²·f·tanθ, a few hundredths of a pixel here.
Vector2d SilhouetteCentre(const SceneCalibration& cal, const Vector3d& centre, double radius) {
  const Vector3d eye = CameraCentre(cal.pose);
  const Vector3d w = (centre - eye).normalized();
  const double d = (centre - eye).norm(), sin_b = radius / d, cos_b = std::sqrt(1 - sin_b * sin_b);
  const Vector3d e1 = w.unitOrthogonal(), e2 = w.cross(e1);
  std::vector<Vector3d> rim;
  for (int k = 0; k < 72; ++k) {
    const double phi = 2 * M_PI * k / 72;
    const Vector3d g = cos_b * w + sin_b * (std::cos(phi) * e1 + std::sin(phi) * e2);
    rim.push_back(eye + g * (d * cos_b));
  }
  std::vector<cv::Point2f> image;
  for (const Vector2d& q : ProjectApparatusPoints(cal.camera, cal.pose, rim)) image.emplace_back(q.x(), q.y());
  const cv::RotatedRect e = cv::fitEllipse(image);
  return Vector2d(e.center.x, e.center.y);
}

constexpr double kRadius = 0.03;  // m: 9 px at 1 m

struct Agreement {
  double rms = 0, worst = 0;  // px, between the blobs' centroids and SilhouetteCentre
};

Agreement Compare(const cv::Mat& grey, const SceneCalibration& cal, const std::vector<Vector3d>& centres) {
  Agreement a;
  for (const Vector3d& p : centres) {
    const Vector2d truth = SilhouetteCentre(cal, p, kRadius);
    const double e = (Centroid(grey, truth, 14) - truth).norm();
    a.rms += e * e;
    a.worst = std::max(a.worst, e);
  }
  a.rms = std::sqrt(a.rms / centres.size());
  return a;
}

PovrayOptions Exact() {
  PovrayOptions o;
  o.antialias_threshold = 0;  // supersample wherever the blob is: 9 × 9 samples at depth 3
  o.antialias_depth = 3;
  return o;
}

class PovrayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!PovrayAvailable()) FAIL() << "povray is not installed (scripts/install-deps.sh installs it)";
  }
};

// POV-Ray's pinhole camera as povray_scene.hpp sets it up is OpenCV's pinhole: a glowing point
// lands on cv::projectPoints' pixel (no distortion, so no remap is involved).
// The footage cache is keyed on the generator's code, not on a version constant someone must
// remember to bump. Truth: coreutils' sha256sum over the generator's files (the list CMake hashes,
// UPHILL_FOOTAGE_GENERATOR_SOURCES), combined as src/footage/CMakeLists.txt states; the clip's
// description (hence its cache key) and the chessboard views' must carry that digest.
TEST(FootageCache, KeyHoldsTheDigestOfTheGeneratorsCode) {
  std::string command = "for f in";
  std::stringstream sources(UPHILL_FOOTAGE_GENERATOR_SOURCES);
  int files = 0;
  for (std::string file; std::getline(sources, file, '|'); ++files) command += " '" + file + "'";
  command += "; do sha256sum \"$f\" | cut -c1-64; done | sha256sum | cut -c1-64";
  ASSERT_GE(files, 20) << "the generator's files were not passed to the test";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char digest[65] = {};
  ASSERT_EQ(std::fread(digest, 1, 64, pipe), 64u);
  ASSERT_EQ(::pclose(pipe), 0);
  const nlohmann::ordered_json description = DescribeFootage(FootageByName("tiny").condition);
  EXPECT_EQ(description.at("generator").get<std::string>(), std::string(digest));
  EXPECT_EQ(description.at("boards").at("generator").get<std::string>(), std::string(digest));
}

TEST_F(PovrayTest, PinholeCameraMatchesProjectPoints) {
  SceneCalibration cal;
  cal.camera = {320, 180, 300.0, 297.0, 163.3, 86.8, {}};
  cal.pose = LookAtPose(Vector3d(0.2, -1.0, 0.3), Vector3d(0.25, 0, 0.05));
  PovrayShot shot;
  shot.camera = cal;
  shot.crop = cv::Rect(0, 0, 320, 180);
  shot.bodies = {std::nullopt};
  const std::vector<Vector3d> points = GridPoints(cal, 1.0);
  const fs::path dir = TempDir("pinhole");
  const PovrayRun run = RunPovray(GlowingSpheres(shot, points, kRadius), shot.crop.size(), 1, dir.string(), Exact());
  cv::Mat grey;
  cv::cvtColor(run.pictures[0], grey, cv::COLOR_BGR2GRAY);
  const Agreement a = Compare(grey, cal, points);
  // Measured: RMS 0.006 px, worst 0.011 px (what remains is the pixel grid in the centroid of a
  // sharp-edged disc). A half-pixel convention error would show as 0.5 px, a wrong focal length
  // or principal point as an error growing toward the edges.
  EXPECT_LT(a.rms, 0.01);
  EXPECT_LT(a.worst, 0.02);
  fs::remove_all(dir);
}

// A window rendered on its own (the per-frame crop) is the same pixels as that part of the full
// picture: the crop offsets the camera exactly, and the anti-aliasing is deterministic.
TEST_F(PovrayTest, CropWindowIsTheFullPictureRegion) {
  NamedFootage tiny = FootageByName("tiny");
  const FootageCondition& c = tiny.condition;
  const LensRemap lens(c.camera.camera);
  PovrayShot full;
  full.camera = {lens.pinhole(), c.camera.pose};
  full.crop = cv::Rect(0, 0, lens.pinhole().width, lens.pinhole().height);
  full.bodies = {BodyPose{c.x0, c.scene.At(c.x0).z, 0.4}};
  PovrayShot crop = full;
  crop.crop = cv::Rect(121, 47, 64, 48);
  const fs::path dir = TempDir("crop");
  const PovrayRun a = RunPovray(PovraySceneText(c.scene, c.apparatus, c.look, full), full.crop.size(), 1,
                                (dir / "full").string());
  const PovrayRun b = RunPovray(PovraySceneText(c.scene, c.apparatus, c.look, crop), crop.crop.size(), 1,
                                (dir / "crop").string());
  // Inner pixels (the adaptive anti-aliasing looks one pixel beyond the window's edge).
  const cv::Rect inner(2, 2, 60, 44);
  cv::Mat diff;
  cv::absdiff(a.pictures[0](crop.crop)(inner), b.pictures[0](inner), diff);
  double largest;
  cv::minMaxLoc(diff.reshape(1), nullptr, &largest);
  EXPECT_LT(largest, 2.0 / 65535) << "the crop differs from the full picture beyond 16-bit rounding";
  fs::remove_all(dir);
}

// Every table cover, body finish and pattern (the random benchmark draws them all) is valid
// scene text that POV-Ray renders, and each draws what it says. Truth: POV-Ray's own pictures of
// the same shot without the body, and with the plain body of the same finish.
TEST_F(PovrayTest, EveryTableFinishAndPatternRenders) {
  NamedFootage tiny = FootageByName("tiny");
  const FootageCondition& c = tiny.condition;
  const LensRemap lens(c.camera.camera);
  PovrayShot shot;
  shot.camera = {lens.pinhole(), c.camera.pose};
  const Vector3d centre(c.x0, 0, c.scene.At(c.x0).z);
  const Vector2d pixel = ProjectApparatusPoint(lens.pinhole(), c.camera.pose, centre);
  const double radius = lens.pinhole().fx * c.scene.body().across / (CameraCentre(c.camera.pose) - centre).norm();
  ASSERT_GT(radius, 8);
  shot.crop = cv::Rect(static_cast<int>(pixel.x()) - 24, static_cast<int>(pixel.y()) - 24, 48, 48);
  shot.bodies = {BodyPose{centre.x(), centre.z(), 0.7}, std::nullopt};
  const cv::Point disc(static_cast<int>(pixel.x()) - shot.crop.x, static_cast<int>(pixel.y()) - shot.crop.y);
  const cv::Rect inside(disc.x - 4, disc.y - 4, 9, 9);  // within the body's disc
  const auto mean_difference = [&](const cv::Mat& a, const cv::Mat& b) {
    cv::Mat diff;
    cv::absdiff(a(inside), b(inside), diff);
    const cv::Scalar m = cv::mean(diff);
    return (m[0] + m[1] + m[2]) / 3;
  };
  struct Case {
    TableCover table;
    BodyFinish finish;
    BodyPattern pattern;
  };
  const fs::path dir = TempDir("looks");
  int k = 0;
  for (const Case& look_case : {Case{TableCover::kWood, BodyFinish::kMatte, BodyPattern::kStripes},
                                Case{TableCover::kCloth, BodyFinish::kGlossy, BodyPattern::kDots},
                                Case{TableCover::kPaper, BodyFinish::kChrome, BodyPattern::kTwoTone},
                                Case{TableCover::kTiles, BodyFinish::kSatin, BodyPattern::kPlain}}) {
    SCOPED_TRACE("look " + std::to_string(k));
    FootageLook look = c.look;
    look.table = look_case.table;
    look.finish = look_case.finish;
    look.pattern = look_case.pattern;
    look.pattern_scale = 0.4 * c.scene.body().across;
    look.pattern_turn = Vector3d(20, 40, 60);
    look.band_rgb = Vector3d(0.6, 0.5, 0.05);
    look.rod_rgb = Vector3d(0.5, 0.1, 0.1);
    look.lamps = {{Vector3d(0.2, -0.5, 0.8), 0.3}};
    const PovrayRun run = RunPovray(PovraySceneText(c.scene, c.apparatus, look, shot), shot.crop.size(), 2,
                                    (dir / std::to_string(k)).string());
    ASSERT_EQ(run.pictures.size(), 2u);
    EXPECT_TRUE(cv::checkRange(run.pictures[0]) && cv::checkRange(run.pictures[1]));
    EXPECT_GT(mean_difference(run.pictures[0], run.pictures[1]), 0.01) << "no body drawn";
    if (look.pattern != BodyPattern::kPlain) {
      FootageLook plain = look;
      plain.pattern = BodyPattern::kPlain;
      PovrayShot one = shot;
      one.bodies = {shot.bodies[0]};
      const PovrayRun base = RunPovray(PovraySceneText(c.scene, c.apparatus, plain, one), one.crop.size(), 1,
                                       (dir / (std::to_string(k) + "-plain")).string());
      EXPECT_GT(mean_difference(run.pictures[0], base.pictures[0]), 0.005) << "the pattern is not drawn";
    }
    ++k;
  }
  fs::remove_all(dir);
}

// Through the lens: POV-Ray's wide pinhole picture remapped by LensRemap puts a point where
// cv::projectPoints with the distortion (k1, k2, p1, p2, k3) puts it, over the whole frame.
TEST_F(PovrayTest, LensRemapMatchesProjectPointsWithDistortion) {
  SceneCalibration cal;
  cal.camera = {320, 180, 288.0, 288.0, 161.4, 88.2, {-0.12, 0.06, 7e-4, -4e-4, -0.015}};
  cal.pose = LookAtPose(Vector3d(0.2, -1.0, 0.3), Vector3d(0.25, 0, 0.05));
  const LensRemap lens(cal.camera);
  PovrayShot shot;
  shot.camera = {lens.pinhole(), cal.pose};
  shot.crop = cv::Rect(0, 0, lens.pinhole().width, lens.pinhole().height);
  shot.bodies = {std::nullopt};
  const std::vector<Vector3d> points = GridPoints(cal, 1.0);
  const fs::path dir = TempDir("lens");
  const PovrayRun run = RunPovray(GlowingSpheres(shot, points, kRadius), shot.crop.size(), 1, dir.string(), Exact());
  cv::Mat grey;
  cv::cvtColor(lens.ToRaw(run.pictures[0]), grey, cv::COLOR_BGR2GRAY);
  const Agreement a = Compare(grey, cal, points);
  // Measured: RMS 0.010 px, worst 0.025 px (the disc's pixel grid, the bilinear remap, and the
  // silhouette's departure from an ellipse under distortion).
  EXPECT_LT(a.rms, 0.015);
  EXPECT_LT(a.worst, 0.04);
  fs::remove_all(dir);
}

// The light model's closed-form flicker integral against the midpoint rule on a fine grid.
TEST(FootageLight, FlickerIntegralMatchesQuadrature) {
  LightModel light;
  light.flicker_depth = 0.3;
  light.drift_depth = 0;
  const double a = 0.0123, b = a + 1.0 / 60;
  double sum = 0;
  constexpr int n = 200000;
  for (int i = 0; i < n; ++i) sum += light.Gain(a + (i + 0.5) * (b - a) / n);
  EXPECT_NEAR(light.Integral(a, b), sum * (b - a) / n, 1e-12);
}

// The sensor: reproducible from its seed, and the noise has the variance of shot + read noise
// (a mid-grey level: σ² = S·full_well + read², in electrons).
TEST(FootageSensor, NoiseIsSeededAndHasTheShotNoiseVariance) {
  SensorModel sensor;
  sensor.full_well = 400;
  sensor.read_noise = 3;
  const double s = SrgbDecode(128.0 / 255);  // linear level of sRGB 128
  const cv::Mat linear(200, 200, CV_32FC3, cv::Scalar::all(s));
  const cv::Mat a = sensor.ToFrame8(linear, 5), b = sensor.ToFrame8(linear, 5), c = sensor.ToFrame8(linear, 6);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0);
  // Back to linear electrons, the variance of the decoded values.
  double sum = 0, sum2 = 0;
  const int n = static_cast<int>(a.total() * 3);
  for (int i = 0; i < n; ++i) {
    const double e = SrgbDecode(a.data[i] / 255.0) * sensor.full_well;
    sum += e, sum2 += e * e;
  }
  const double mean = sum / n, variance = sum2 / n - mean * mean;
  const double expected = s * sensor.full_well + 9;
  EXPECT_NEAR(mean, s * sensor.full_well, 0.01 * s * sensor.full_well);
  // 120 000 samples: the variance is known to ±1 %; 8-bit quantisation adds ~1 %.
  EXPECT_NEAR(variance, expected, 0.05 * expected);
}

// Motion blur as the footage composes it (each sub-frame's own window rendered, remapped,
// pasted into the static scene, weighted per row) equals the plain average of whole frames
// rendered by POV-Ray at the same sub-frame times: the windows hold all of the body's picture
// (its soft shadow and reflections included) and the weights are right. A fast ball (fast-360-30's
// scene at 320 × 180, 1.0 m/s, a 360° shutter: a blur of ~10 px), lossless and without noise;
// 8 sub-frames in both.
TEST_F(PovrayTest, MotionBlurEqualsTheAverageOfWholeFrames) {
  FootageCondition c = FootageByName("fast-360-30").condition;
  c.name = "blur-check";
  c.camera.camera = {320, 180, 288.0, 288.0, 161.4, 88.2, {-0.12, 0.06, 7e-4, -4e-4, -0.015}};
  c.shutter.height = 180;
  c.codec = VideoCodec::kFfv1;
  c.sensor.noise = false;
  c.release_time = -0.55;  // already rolling fast at frame 0
  c.frames = 2;
  c.boards = 0;
  c.max_step_px = 1e-3;  // as many sub-frames as allowed:
  c.max_subframes = 8;   // exactly 8
  const fs::path dir = TempDir("blur");
  const std::string cache = (dir / "cache").string();
  // render_clip --plan's count, checked against what the render then does: the POV-Ray programs
  // RenderFootage ran (counted as it starts them), the sub-frames it composed (8 per frame: the
  // cap above), and nothing left to render once the clip and its pictures are cached.
  const FootageWork plan = PlanFootage(c, cache);
  const FootageFiles files = RenderFootage(c, cache);
  EXPECT_FALSE(plan.clip_cached);
  EXPECT_EQ(plan.static_to_render, 1);
  EXPECT_EQ(plan.static_to_render + plan.runs_to_render, files.povray_runs);
  EXPECT_EQ(plan.subframes, files.subframes);
  ASSERT_EQ(plan.frames.size(), 2u);
  for (const FootageFrameWork& f : plan.frames) EXPECT_GE(f.subframes, 8) << "frame " << f.frame;
  const FootageWork after = PlanFootage(c, cache);
  EXPECT_TRUE(after.clip_cached);
  EXPECT_EQ(after.static_to_render + after.runs_to_render + after.subframes_to_render, 0);
  EXPECT_EQ(after.subframes, plan.subframes);
  cv::VideoCapture video(files.video, cv::CAP_FFMPEG);
  cv::Mat frame;
  ASSERT_TRUE(video.read(frame) && video.read(frame));  // frame 1
  // The same exposure by whole frames: t_f = 1/30 s, E = 1/30 s, 8 equal slots.
  const Motion motion(c.scene, c.x0);
  const LensRemap lens(c.camera.camera);
  PovrayShot shot;
  shot.camera = {lens.pinhole(), c.camera.pose};
  shot.crop = cv::Rect(0, 0, lens.pinhole().width, lens.pinhole().height);
  const double t = 1.0 / 30, E = c.shutter.exposure;
  for (int k = 0; k < 8; ++k) {
    const MotionSample m = motion.At(t - E / 2 + (k + 0.5) * E / 8 - c.release_time);
    shot.bodies.push_back(BodyPose{m.x, m.z, m.angle});
  }
  const PovrayRun run = RunPovray(PovraySceneText(c.scene, c.apparatus, c.look, shot), shot.crop.size(), 8,
                                  (dir / "whole").string(), c.povray);
  cv::Mat sum = cv::Mat::zeros(180, 320, CV_32FC3);
  for (const cv::Mat& p : run.pictures) sum += lens.ToRaw(p) / 8.0;
  std::vector<cv::Mat> channels(3);
  cv::split(sum, channels);
  for (cv::Mat& ch : channels) ch = ch.mul(lens.Vignetting(c.vignetting), c.gain);
  cv::merge(channels, sum);
  const cv::Mat expected = c.sensor.ToFrame8(sum, 1);
  cv::Mat diff;
  cv::absdiff(frame, expected, diff);
  double largest;
  cv::minMaxLoc(diff.reshape(1), nullptr, &largest);
  const double rms = std::sqrt(cv::mean(diff.mul(diff))[0]);
  // Both are 8-bit roundings of the same linear picture: at most one level apart, but for a few
  // pixels of the rods, which the body's light reaches by paths the windows do not bound (its
  // light reflected from one rod onto the other, the faintest edge of its penumbra). Measured:
  // one pixel of the 57 600 two levels apart (blue, on the rod beside the body).
  int beyond_one_level = 0;
  for (int v = 0; v < diff.rows; ++v)
    for (int u = 0; u < diff.cols; ++u) {
      const cv::Vec3b d = diff.at<cv::Vec3b>(v, u);
      beyond_one_level += std::max({d[0], d[1], d[2]}) > 1;
    }
  EXPECT_LE(largest, 2.0);
  EXPECT_LE(beyond_one_level, 3);
  EXPECT_LT(rms, 0.2);
  // And the blur is there: the frame differs from the body at rest at mid-exposure.
  const std::vector<ClipTruth> truth = ReadFootageTruth(files.truth_csv);
  const MotionSample a = motion.At(t - E / 2 - c.release_time), b = motion.At(t + E / 2 - c.release_time);
  const double blur_px = (ProjectApparatusPoint(c.camera.camera, c.camera.pose, Vector3d(b.x, 0, b.z)) -
                          ProjectApparatusPoint(c.camera.camera, c.camera.pose, Vector3d(a.x, 0, a.z)))
                             .norm();
  EXPECT_GT(blur_px, 8.0) << "the check needs a long blur";
  EXPECT_TRUE(truth[1].present);
  fs::remove_all(dir);
}

// The user's path on a small rendered clip (320 × 180, 10 frames, the lab's grey-level contrast
// ball on wood, H.264): chessboard views -> `uphill calibrate camera`, apparatus points ->
// `uphill calibrate scene`, the clip -> `uphill track`; the track against the renderer's truth.
TEST_F(PovrayTest, UserPathOnATinyClip) {
  const fs::path dir = TempDir("clip");
  const NamedFootage tiny = FootageByName("tiny");
  const FootageFiles files = RenderFootage(tiny.condition, (dir / "cache").string());
  ASSERT_EQ(files.boards.size(), 10u);
  std::string boards;
  for (const std::string& b : files.boards) boards += " '" + b + "'";
  const std::string cam = (dir / "cam.json").string(), scene = (dir / "scene.json").string();
  const std::string track = (dir / "track.csv").string();
  auto r = testing::RunUphill("calibrate camera" + boards + " --cols 9 --rows 6 --square 20mm -o '" + cam + "'");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  r = testing::RunUphill("calibrate scene --camera '" + cam + "' --points '" + files.points_csv + "' --frame '" +
                         files.first_frame + "' -o '" + scene + "'");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  r = testing::RunUphill("track '" + files.video + "' --camera '" + cam + "' --scene '" + scene + "' " +
                         FootageSceneFlags(tiny.condition) + " -o '" + track + "'");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::vector<ClipTruth> truth = ReadFootageTruth(files.truth_csv);
  const CsvTable table = ReadCsvFile(track);
  ASSERT_EQ(table.rows.size(), truth.size());
  double s_px = 0, s_mm = 0;
  int found = 0, compared = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const std::vector<std::string>& cells = table.rows[i].cells;
    if (cells[table.Column("u")].empty()) continue;
    ++found;
    if (!truth[i].present || truth[i].visibility < 0.5) continue;
    const double du = std::stod(cells[table.Column("u")]) - truth[i].u;
    const double dv = std::stod(cells[table.Column("v")]) - truth[i].v;
    const double dx = std::stod(cells[table.Column("x")]) - truth[i].x * 1e3;
    const double dz = std::stod(cells[table.Column("z")]) - truth[i].z * 1e3;
    s_px += du * du + dv * dv, s_mm += dx * dx + dz * dz;
    ++compared;
  }
  ASSERT_GT(compared, 0);
  const double rms_px = std::sqrt(s_px / compared), rms_mm = std::sqrt(s_mm / compared);
  std::printf("tiny clip: %d/%zu frames found, RMS %.3f px, %.3f mm\n", found, truth.size(), rms_px, rms_mm);
  // About 1.5 times what the tracker measures on this seeded clip: 10/10 frames, RMS 0.092 px,
  // 0.123 mm (the lab's grey-level ball).
  EXPECT_EQ(found, 10);
  EXPECT_LT(rms_px, 0.14);
  EXPECT_LT(rms_mm, 0.19);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
