// The ball tracker on synthetic clips rendered at test time (src/footage/synthetic_clip.hpp):
// accuracy against the exact ground truth, lost frames, partial and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "model/input_error.hpp"
#include "footage/sensor_model.hpp"
#include "footage/synthetic_clip.hpp"
#include "vision/camera.hpp"
#include "vision/video_tracking.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

fs::path TempDir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("uphill_vision_track_test_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// Removes the clips when the program ends.
class RemoveTempDir : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(TempDir(), ec);
  }
};
const auto* const kRemoveTempDir = ::testing::AddGlobalTestEnvironment(new RemoveTempDir);

struct Errors {
  double rms_uv = 0, rms_xz_mm = 0, max_uv = 0;
  int compared = 0, truth_present = 0, found = 0;
};

// Frames where the ball is present and at least half its outline is visible are compared.
Errors Compare(const std::vector<ClipTruth>& truth, const TrackResult& track) {
  Errors e;
  double s_uv = 0, s_xz = 0;
  for (size_t i = 0; i < truth.size() && i < track.rows.size(); ++i) {
    const ClipTruth& t = truth[i];
    const BallObservation& b = track.rows[i].ball;
    e.truth_present += t.present;
    e.found += b.found;
    if (!t.present || t.visibility < 0.5 || !b.found) continue;
    const double duv2 = std::pow(b.u - t.u, 2) + std::pow(b.v - t.v, 2);
    s_uv += duv2;
    e.max_uv = std::max(e.max_uv, std::sqrt(duv2));
    s_xz += (std::pow(b.x - t.x, 2) + std::pow(b.z - t.z, 2)) * 1e6;
    ++e.compared;
  }
  if (e.compared) {
    e.rms_uv = std::sqrt(s_uv / e.compared);
    e.rms_xz_mm = std::sqrt(s_xz / e.compared);
  }
  std::printf("  compared %d frames: RMS (u, v) %.4f px (max %.4f), RMS (x, z) %.4f mm\n", e.compared, e.rms_uv,
              e.max_uv, e.rms_xz_mm);
  return e;
}

struct ClipRun {
  std::vector<ClipTruth> truth;
  TrackResult track;
  Errors errors;
};

ClipRun RenderAndTrack(const ClipRenderer& renderer, const Scene& scene, const Motion& motion, const ClipSettings& s,
                   const std::string& file, const TrackVideoOptions& options = {}) {
  ClipRun run;
  const std::string video = (TempDir() / file).string();
  run.truth = RenderClip(renderer, motion, s, video);
  run.track = TrackVideo(video, scene, renderer.calibration(), options);
  run.errors = Compare(run.truth, run.track);
  return run;
}

// Found wherever the ball is in the picture; compared in at least min_frames; within the bounds.
// Each test's bounds are about 1.5 times what the tracker measures on its clip (stated beside
// them; the clips are seeded, so a run measures the same), so that a regression of half as much
// again fails.
void ExpectAccurate(const Errors& e, int min_frames, double max_rms_uv_px, double max_rms_xz_mm) {
  EXPECT_EQ(e.found, e.truth_present);
  EXPECT_GE(e.compared, min_frames);
  EXPECT_LE(e.rms_uv, max_rms_uv_px) << "max " << e.max_uv;
  EXPECT_LE(e.rms_xz_mm, max_rms_xz_mm);
}

// f() throws InputError whose message contains each of `parts`.
template <typename F>
void ExpectInputError(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    for (const std::string& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// One renderer for the default 1280×720 view (the ray map and background cost ~2 s).
class DefaultView : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setup_ = std::make_unique<ClipSetup>(DefaultClipSetup(1280, 720));
    renderer_ = std::make_unique<ClipRenderer>(setup_->scene, setup_->calibration, setup_->apparatus);
  }
  static void TearDownTestSuite() {
    renderer_.reset();
    setup_.reset();
  }
  static std::unique_ptr<ClipSetup> setup_;
  static std::unique_ptr<ClipRenderer> renderer_;
};
std::unique_ptr<ClipSetup> DefaultView::setup_;
std::unique_ptr<ClipRenderer> DefaultView::renderer_;

TEST_F(DefaultView, CleanLosslessClipWithinATenthOfAPixel) {
  ClipSettings s;
  s.frames = 30;
  s.release_time = -0.9;  // already rolling toward O, up to 10 px per frame
  const Motion motion(setup_->scene, setup_->x0);
  const ClipRun run = RenderAndTrack(*renderer_, setup_->scene, motion, s, "clean.avi");
  ASSERT_EQ(run.track.rows.size(), run.truth.size());
  ExpectAccurate(run.errors, 27, 0.05, 0.05);  // measured: 0.032 px, 0.033 mm
  EXPECT_FALSE(run.track.partial) << run.track.partial_reason;
  for (const TrackRow& r : run.track.rows) {
    EXPECT_NEAR(r.t, r.frame / 30.0, 1e-3);
    if (r.ball.found) {
      EXPECT_GT(r.ball.quality, 0.5);
    }
  }
}

// A scene calibration that puts the rails' path a few pixels off the ball (its camera moved
// across the picture): a position is reported only where it lies on the path, and that check
// follows the clip's own offset, so the ball is still reported. Where the offset is within 2.5 px
// (kOnPathFirstPx) from the first frame, beyond it from the eleventh (kOnPathAdoptFrames).
// Truth: the renderer's centres (the calibration moves the path, not the picture).
TEST_F(DefaultView, APathCalibratedAFewPixelsOffStillReportsTheBall) {
  ClipSettings s;
  s.frames = 30;
  s.release_time = -0.9;
  const Motion motion(setup_->scene, setup_->x0);
  const std::string video = (TempDir() / "path_off.avi").string();
  const std::vector<ClipTruth> truth = RenderClip(*renderer_, motion, s, video);
  for (const double shift_px : {2.0, 4.0}) {
    SceneCalibration shifted = setup_->calibration;
    // The camera moved along its own y by d moves the picture of a point at depth Z by fy·d/Z px.
    const Eigen::Vector3d at = shifted.pose.rotation * Eigen::Vector3d(setup_->x0, 0, 0) + shifted.pose.translation;
    shifted.pose.translation.y() += shift_px * at.z() / shifted.camera.fy;
    const TrackResult track = TrackVideo(video, setup_->scene, shifted);
    ASSERT_EQ(track.rows.size(), truth.size());
    const Errors e = Compare(truth, track);
    const int first = shift_px < 2.5 ? 0 : 10;
    for (int f = first; f < s.frames; ++f) EXPECT_TRUE(track.rows[f].ball.found) << shift_px << " px off, frame " << f;
    EXPECT_LT(e.rms_uv, 0.1) << shift_px << " px off";
  }
}

// TrackerOptions::min_report_quality: a frame of a doubted fit is withdrawn where it lies off the
// motion of the frames around it, and kept where it lies on it. Truth: a clean clip whose frame
// 15 is altered after rendering, the ball's region moved 2 px along its own motion (so that it
// stays on the rails' path and only the motion tells it); with every fit doubted (1), that frame
// alone is withdrawn, and with none (0) it is reported about 2 px off.
TEST_F(DefaultView, ADoubtedFitOffTheMotionAroundItIsWithdrawn) {
  ClipSettings s;
  s.frames = 30;
  s.release_time = -0.9;  // rolling toward O, up to 10 px per frame
  const Motion motion(setup_->scene, setup_->x0);
  const std::string clean = (TempDir() / "doubted_clean.avi").string();
  const std::vector<ClipTruth> truth = RenderClip(*renderer_, motion, s, clean);
  constexpr int kMoved = 15;
  const Eigen::Vector2d along =
      Eigen::Vector2d(truth[kMoved + 1].u - truth[kMoved - 1].u, truth[kMoved + 1].v - truth[kMoved - 1].v).normalized();
  const Eigen::Vector2d shift = 2.0 * along;
  const std::string moved = (TempDir() / "doubted_moved.avi").string();
  {
    cv::VideoCapture in(clean);
    cv::VideoWriter out(moved, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30,
                        cv::Size(setup_->calibration.camera.width, setup_->calibration.camera.height));
    ASSERT_TRUE(in.isOpened() && out.isOpened());
    cv::Mat frame;
    for (int f = 0; in.read(frame); ++f) {
      if (f == kMoved) {
        cv::Mat shifted;
        const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, shift.x(), 0, 1, shift.y());
        cv::warpAffine(frame, shifted, m, frame.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
        const int r = 60;  // px, beyond the ball's radius (about 40 px) and its shift
        const cv::Rect box = cv::Rect(static_cast<int>(truth[f].u) - r, static_cast<int>(truth[f].v) - r, 2 * r, 2 * r) &
                             cv::Rect(0, 0, frame.cols, frame.rows);
        shifted(box).copyTo(frame(box));
      }
      out.write(frame);
    }
  }
  TrackVideoOptions none, every;
  none.tracker.min_report_quality = 0;
  every.tracker.min_report_quality = 1;
  const TrackResult kept = TrackVideo(moved, setup_->scene, setup_->calibration, none);
  const TrackResult judged = TrackVideo(moved, setup_->scene, setup_->calibration, every);
  ASSERT_EQ(kept.rows.size(), truth.size());
  ASSERT_EQ(judged.rows.size(), truth.size());
  ASSERT_TRUE(kept.rows[kMoved].ball.found);
  const BallObservation& k = kept.rows[kMoved].ball;
  EXPECT_NEAR(k.u - truth[kMoved].u, shift.x(), 0.3);
  EXPECT_NEAR(k.v - truth[kMoved].v, shift.y(), 0.3);
  EXPECT_EQ(kept.frames_of_poor_fit, 0);
  for (size_t f = 0; f < truth.size(); ++f)
    EXPECT_EQ(judged.rows[f].ball.found, f != kMoved) << "frame " << f << ", quality " << kept.rows[f].ball.quality;
  EXPECT_EQ(judged.frames_of_poor_fit, 1);
}

TEST_F(DefaultView, BlurNoiseFlickerAndH264WithinThreeTenthsOfAPixel) {
  ClipSettings s;
  s.frames = 30;
  s.release_time = -0.9;
  s.blur_samples = 6;
  s.exposure = 1.0 / 60;
  s.noise_sigma = 3;
  s.flicker = 0.02;
  s.seed = 7;
  const Motion motion(setup_->scene, setup_->x0);
  // measured: 0.079 px, 0.083 mm
  ExpectAccurate(RenderAndTrack(*renderer_, setup_->scene, motion, s, "noisy.mp4").errors, 27, 0.12, 0.125);
}

// With a rolling shutter each row's time is the frame's plus the centre row's delay, also on the
// frames whose time the container does not give (FFmpeg gives none for the last frames of an
// H.264 stream with B-frames: they are extrapolated from the frame before). Truth: the frame
// rate and the readout given, t = frame/fps + v·readout/height.
TEST_F(DefaultView, RowTimesOfARollingShutterHoldOnFramesWithoutTimestamps) {
  ClipSettings s;
  s.frames = 12;
  s.release_time = -0.9;
  s.noise_sigma = 2;
  const Motion motion(setup_->scene, setup_->x0);
  TrackVideoOptions options;
  options.tracker.readout = 0.02;
  const ClipRun run = RenderAndTrack(*renderer_, setup_->scene, motion, s, "rows.mp4", options);
  EXPECT_GT(run.track.extrapolated_times, 0) << "the case needs frames without timestamps";
  int checked = 0;
  for (const TrackRow& r : run.track.rows) {
    if (!r.ball.found) continue;
    EXPECT_NEAR(r.ball.time_offset, r.ball.v * 0.02 / 720, 1e-4) << "frame " << r.frame;
    EXPECT_NEAR(r.t, r.frame / 30.0 + r.ball.time_offset, 1e-3) << "frame " << r.frame;
    ++checked;
  }
  EXPECT_EQ(checked, s.frames);
  EXPECT_LE(run.errors.rms_uv, 0.15);  // measured: 0.095 px
}

// A rolling shutter asked to be measured (--readout auto) on a clip whose ball never moves shows
// no shear: the readout is then taken as half a frame, with the standard deviation of a value
// uniform over 0 … 1/fps (a video's rows are all read within its frame time), and every row's
// time carries it. Truth: those closed forms, t = frame/fps + v·readout/height.
TEST_F(DefaultView, AReadoutThatCannotBeMeasuredIsHalfAFrameWithItsRange) {
  ClipSettings s;
  s.frames = 8;
  s.release_time = 10;  // at rest throughout
  const Motion motion(setup_->scene, setup_->x0);
  TrackVideoOptions options;
  options.tracker.measure_readout = true;
  const ClipRun run = RenderAndTrack(*renderer_, setup_->scene, motion, s, "rest_rows.avi", options);
  EXPECT_EQ(run.track.measured_readout_frames, 0);
  EXPECT_DOUBLE_EQ(run.track.readout, 0.5 / 30);
  ASSERT_TRUE(run.track.readout_u.has_value());
  EXPECT_NEAR(*run.track.readout_u, 1 / (30 * std::sqrt(12.0)), 1e-12);
  int checked = 0;
  for (const TrackRow& r : run.track.rows) {
    if (!r.ball.found) continue;
    EXPECT_NEAR(r.t, r.frame / 30.0 + r.ball.v * (0.5 / 30) / 720, 1e-4) << "frame " << r.frame;
    ++checked;
  }
  EXPECT_EQ(checked, s.frames);
  const std::string csv = (TempDir() / "rest_rows.csv").string();
  WriteTrack(csv, run.track, {"rest_rows.avi", "cam.json", "scene.json", "sphere"});
  std::ifstream side_in(csv + ".json");
  const nlohmann::json side = nlohmann::json::parse(side_in);
  EXPECT_EQ(side["models"]["rolling_shutter"], "not measurable (too little shear): half a frame assumed");
  EXPECT_NEAR(side["readout_u_s"].get<double>(), 1 / (30 * std::sqrt(12.0)), 1e-12);
  EXPECT_EQ(side["image_height_px"], 720);
}

TEST_F(DefaultView, InitialGuessAndLostBallKeepTheirRows) {
  // Released beyond X: it rolls up the rails and drops between them; the last frames have no ball.
  const double x_eq = *setup_->scene.x_eq(), x_max = setup_->scene.x_max();
  const Motion motion(setup_->scene, x_eq + 0.5 * (x_max - x_eq));
  ClipSettings s;
  s.frames = static_cast<int>(std::ceil(motion.end_time() * s.fps)) + 6;
  const std::string video = (TempDir() / "falls.avi").string();
  const std::vector<ClipTruth> truth = RenderClip(*renderer_, motion, s, video);
  ASSERT_FALSE(truth.back().present);
  TrackVideoOptions options;
  options.tracker.init_uv = Eigen::Vector2d(truth[0].u + 6, truth[0].v - 4);
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration, options);
  ASSERT_EQ(track.rows.size(), truth.size());
  int absent = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (truth[i].present) continue;
    ++absent;
    EXPECT_FALSE(track.rows[i].ball.found) << "frame " << i;
    EXPECT_EQ(track.rows[i].ball.quality, 0.0);
  }
  EXPECT_GE(absent, 5);
  EXPECT_TRUE(track.partial);
  EXPECT_NE(track.partial_reason.find("lost"), std::string::npos) << track.partial_reason;
  const Errors e = Compare(truth, track);
  EXPECT_LE(e.rms_uv, 0.08);  // measured: 0.055 px

  const std::string csv = (TempDir() / "falls.csv").string();
  WriteTrack(csv, track, {video, "cam.json", "scene.json", "sphere"});
  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  EXPECT_EQ(header, "frame,t,u,v,radius_px,x,z,quality,u_px,u_x,u_outline_px");
  int lines = 0;
  while (std::getline(in, line)) last = line, ++lines;
  EXPECT_EQ(lines, static_cast<int>(truth.size()));
  EXPECT_NE(last.find(",,,,,,0,,,"), std::string::npos) << last;
  // Each found row's uncertainty: the documented model (video_tracking.hpp, TrackRow), computed
  // here from the rows' own pixels: 0.08 px + 0.007 × the pixels moved per frame between the found
  // neighbours, or the frame's outline spread where larger, with 0.10 px in quadrature, and in mm
  // at the body's scale.
  std::vector<const TrackRow*> found_rows;
  for (const TrackRow& r : track.rows)
    if (r.ball.found) found_rows.push_back(&r);
  for (std::size_t i = 0; i < found_rows.size(); ++i) {
    const TrackRow& a = *found_rows[i == 0 ? 0 : i - 1];
    const TrackRow& b = *found_rows[std::min(i + 1, found_rows.size() - 1)];
    const double per_frame = std::hypot(b.ball.u - a.ball.u, b.ball.v - a.ball.v) / (b.t - a.t) / s.fps;
    const double systematic = std::max(0.08 + 0.007 * per_frame, found_rows[i]->ball.outline_spread_px);
    EXPECT_NEAR(found_rows[i]->u_px, std::hypot(systematic, 0.10), 1e-3) << "frame " << found_rows[i]->frame;
    EXPECT_NEAR(found_rows[i]->u_x, found_rows[i]->u_px * setup_->scene.body().across / found_rows[i]->ball.radius_px, 1e-9);
  }
  std::ifstream side_in(csv + ".json");
  const nlohmann::json side = nlohmann::json::parse(side_in);
  EXPECT_EQ(side["format"], "uphill-track/1");
  EXPECT_EQ(side["partial"], true);
  // The models the clip needed: no readout given or asked for, and every found frame measured by
  // one of the two measurements (the rows' own flags are the truth).
  EXPECT_EQ(side["models"]["rolling_shutter"], "global");
  int by_model = 0, found = 0;
  for (const TrackRow& r : track.rows) by_model += r.ball.found && r.ball.full_model, found += r.ball.found;
  EXPECT_EQ(side["models"]["frames_by_outline_model"], by_model);
  EXPECT_EQ(side["models"]["frames_by_edge_fit"], found - by_model);
  EXPECT_EQ(side["frames_with_ball"], found);
}

// Paints the upper half (in the picture) of a sphere of radius r centred at c dark, up to
// `inset_px` from its limb: a pixel's share is the share of its 4 × 4 sub-pixel rays within the
// cone of rays that touch the sphere, narrowed by the inset (the outline of ball_tracker.hpp,
// computed here on its own).
void PaintUpperHalfDark(cv::Mat& frame, const SceneCalibration& cal, const Eigen::Vector3d& c, double r, double inset_px) {
  const Eigen::Vector3d eye = CameraCentre(cal.pose);
  const Eigen::Vector3d axis = (c - eye).normalized();
  const double cos_half = std::cos(std::asin(r / (c - eye).norm()) - inset_px / cal.camera.fx);
  const Eigen::Vector2d centre = ProjectApparatusPoint(cal.camera, cal.pose, c);
  const int reach = static_cast<int>(r * cal.camera.fx / (c - eye).norm()) + 3;
  for (int y = static_cast<int>(centre.y()) - reach; y <= static_cast<int>(centre.y()); ++y) {
    for (int x = static_cast<int>(centre.x()) - reach; x <= static_cast<int>(centre.x()) + reach; ++x) {
      int inside = 0;
      for (int k = 0; k < 16; ++k) {
        const Eigen::Vector2d p(x - 0.375 + 0.25 * (k % 4), y - 0.375 + 0.25 * (k / 4));
        if (p.y() > centre.y()) continue;
        const Eigen::Vector2d n = UndistortPixel(cal.camera, p);
        const Eigen::Vector3d ray = (cal.pose.rotation.transpose() * Eigen::Vector3d(n.x(), n.y(), 1)).normalized();
        inside += ray.dot(axis) > cos_half;
      }
      cv::Vec3b& px = frame.at<cv::Vec3b>(y, x);
      for (int ch = 0; ch < 3; ++ch) px[ch] = cv::saturate_cast<uchar>(px[ch] + (20 - px[ch]) * inside / 16.0);
    }
  }
}

// A body at rest from the first frame hides the background under it, so the first frames are
// measured without it; a print on the body that turns out of view as it rolls (here: its upper
// half dark while it rests, up to a ring 2 px wide at the limb) misleads that measurement: the 12
// frames at rest are lost. The opening is measured again at the end, backwards from the first
// frames the background confirms (ball_tracker.hpp, "The opening"), and every frame is found.
// The ring, narrower than the rays' limb window, biases the limb colour's fit on the frames at
// rest (0.8 px; 0.03 px on the moving frames), hence the bounds. Truth: the renderer's positions;
// the print is painted on the rendered frames by this test.
TEST_F(DefaultView, AnOpeningOnAPrintedBodyAtRestIsMeasuredAgainFromTheBackground) {
  ClipSettings s;
  // At rest for 12 frames, then it rolls toward O, 6 radii in the first second: the background
  // under its resting place is seen once it has rolled away.
  s.frames = 45;
  s.release_time = 0.4;
  s.noise_sigma = 1;
  const Motion motion(setup_->scene, setup_->x0 - 0.1);
  const std::string rendered = (TempDir() / "opening_rendered.avi").string();
  const std::vector<ClipTruth> truth = RenderClip(*renderer_, motion, s, rendered);
  const std::string video = (TempDir() / "opening.avi").string();
  {
    cv::VideoCapture in(rendered);
    cv::VideoWriter out(video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), s.fps,
                        cv::Size(setup_->calibration.camera.width, setup_->calibration.camera.height));
    cv::Mat frame;
    for (int i = 0; in.read(frame); ++i) {
      if (truth[i].t < s.release_time)
        PaintUpperHalfDark(frame, setup_->calibration, Eigen::Vector3d(truth[i].x, 0, truth[i].z), setup_->scene.body().across, 2);
      out.write(frame);
    }
  }
  const Errors e = Compare(truth, TrackVideo(video, setup_->scene, setup_->calibration));
  ExpectAccurate(e, s.frames - 2, 0.6, 0.6);  // measured: 0.39 px, 0.41 mm
  EXPECT_LE(e.max_uv, 1.2);                   // measured: 0.80 px
}

// Before any frame is accepted the clip's noise is not known: a first fit is judged against its
// own residual level, not the tracker's guess (a linear-light RMS of 0.01), so a body in a noisy
// clip is found from the first frame (without that, this clip's ball is found in none of its
// frames). Truth: the renderer's positions; sensor noise of 24 levels of 255 is several times the
// guess in linear light.
TEST_F(DefaultView, ANoisyClipIsFoundFromItsFirstFrame) {
  ClipSettings s;
  s.frames = 12;
  s.release_time = -0.9;
  s.noise_sigma = 24;
  s.seed = 11;
  const Motion motion(setup_->scene, setup_->x0);
  const ClipRun run = RenderAndTrack(*renderer_, setup_->scene, motion, s, "noisy_first.avi");
  ASSERT_FALSE(run.track.rows.empty());
  EXPECT_TRUE(run.track.rows[0].ball.found);
  ExpectAccurate(run.errors, s.frames, 0.12, 0.12);  // measured: 0.077 px, 0.081 mm
}

// A body in dim light, at rest from the first frame: the default scene's clip with every frame
// darkened in linear light to 0.15 (a lamp of 0.15 of the power, read back through the sRGB
// curve the renderer wrote), so that its outline steps by fewer grey levels than the fast path
// asks for, and its fit stands out by 9.1 noise levels (10 needed without a found outline). Truth:
// the renderer's centres (the darkening moves nothing). The search found no body in such a clip
// until an outline whose edges lie on it sharply counted from half that contrast (at 0.2 of the
// power, 18 levels, it was found before too).
TEST_F(DefaultView, ABodyInDimLightIsFoundFromItsFirstFrame) {
  ClipSettings s;
  s.frames = 6;
  s.release_time = 10;  // at rest through the clip
  const Motion motion(setup_->scene, setup_->x0);
  const std::string lit = (TempDir() / "dim_light_source.avi").string(), dim = (TempDir() / "dim_light.avi").string();
  const std::vector<ClipTruth> truth = RenderClip(*renderer_, motion, s, lit);
  const double power = 0.15;  // the outline's step: 13.9 grey levels (20 for an outline found)
  cv::Mat darken(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i)
    darken.at<std::uint8_t>(i) = cv::saturate_cast<std::uint8_t>(255 * SrgbEncode(power * SrgbDecode(i / 255.0)));
  cv::VideoCapture in(lit);
  cv::VideoWriter out;
  cv::Mat frame;
  while (in.read(frame)) {
    if (!out.isOpened()) out.open(dim, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), s.fps, frame.size());
    cv::LUT(frame, darken, frame);
    out.write(frame);
  }
  out.release();
  const TrackResult track = TrackVideo(dim, setup_->scene, renderer_->calibration(), {});
  ASSERT_FALSE(track.rows.empty());
  EXPECT_TRUE(track.rows[0].ball.found);
  ExpectAccurate(Compare(truth, track), s.frames, 0.09, 0.09);  // measured: 0.056 px, 0.059 mm
}

// A video cut mid-file keeps every frame that can be read, and says it is partial because of the
// input (exit status 2 of `uphill track`). Truth: the frames OpenCV's decoder reads from the cut
// file on its own, and the whole clip's positions for those frames.
TEST_F(DefaultView, TruncatedVideoIsPartial) {
  ClipSettings s;
  s.frames = 20;
  const Motion motion(setup_->scene, setup_->x0);
  const std::string video = (TempDir() / "truncated.avi").string();
  RenderClip(*renderer_, motion, s, video);
  const TrackResult whole = TrackVideo(video, setup_->scene, setup_->calibration);
  ASSERT_EQ(whole.rows.size(), 20u);
  fs::resize_file(video, fs::file_size(video) * 6 / 10);
  int readable = 0;
  {
    cv::VideoCapture capture(video);
    for (cv::Mat frame; capture.read(frame) && !frame.empty();) ++readable;
  }
  ASSERT_GT(readable, 0);
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration);
  EXPECT_TRUE(track.partial);
  EXPECT_TRUE(track.input_problem);
  EXPECT_EQ(track.rows.size(), static_cast<std::size_t>(readable));
  EXPECT_LT(track.rows.size(), 20u);
  for (std::size_t i = 0; i < track.rows.size(); ++i) {
    EXPECT_EQ(track.rows[i].ball.found, whole.rows[i].ball.found) << "frame " << i;
    EXPECT_NEAR(track.rows[i].ball.x, whole.rows[i].ball.x, 1e-5) << "frame " << i;  // m
  }
  EXPECT_NE(track.partial_reason.find("truncated"), std::string::npos) << track.partial_reason;
}

TEST_F(DefaultView, VideoWithoutBallIsPartialWithoutPositions) {
  const std::string video = (TempDir() / "empty.avi").string();
  {
    cv::VideoWriter w(video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30, cv::Size(1280, 720));
    cv::RNG rng(1);
    const cv::Mat frame = ToFrame8(renderer_->RenderLinear({}), 1.0, 1.0, rng);
    for (int i = 0; i < 5; ++i) w.write(frame);
  }
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration);
  ASSERT_EQ(track.rows.size(), 5u);
  for (const TrackRow& r : track.rows) EXPECT_FALSE(r.ball.found);
  EXPECT_TRUE(track.partial);
  EXPECT_TRUE(track.input_problem);
  EXPECT_NE(track.partial_reason.find("found in none"), std::string::npos) << track.partial_reason;
}

// A rolling ball, frames written by hand so that the picture can be changed from frame `from` on
// by `change` (the linear-light picture, in place, before the camera's encoding), and its noise
// (σ, 8-bit levels) with it. Truth: the renderer's centres (ClipRenderer) and the
// frame where the change was made.
std::vector<Eigen::Vector2d> WriteChangedClip(const ClipRenderer& renderer, const ClipSetup& setup, const std::string& video,
                                              int frames, int from, const std::function<void(cv::Mat&)>& change,
                                              double noise_before = 1.0, double noise_from = 1.0) {
  const Motion motion(setup.scene, setup.x0);
  cv::VideoWriter w(video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30, cv::Size(1280, 720));
  cv::RNG rng(3);
  std::vector<Eigen::Vector2d> uv;
  for (int i = 0; i < frames; ++i) {
    const MotionSample m = motion.At(i / 30.0);
    const double x = m.x, z = m.z;
    cv::Mat linear = renderer.RenderLinear({Eigen::Vector2d(x, z)});
    if (i >= from) change(linear);
    w.write(ToFrame8(linear, 1.0, i < from ? noise_before : noise_from, rng));
    uv.push_back(ProjectApparatusPoint(setup.calibration.camera, setup.calibration.pose, Eigen::Vector3d(x, 0, z)));
  }
  return uv;
}

// The largest distance of a frame's centre from its true pixel; every frame must be found.
double LargestError(const TrackResult& track, const std::vector<Eigen::Vector2d>& uv) {
  double worst = 0;
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const BallObservation& b = track.rows[i].ball;
    EXPECT_TRUE(b.found) << "frame " << i;
    if (b.found) worst = std::max(worst, std::hypot(b.u - uv[i].x(), b.v - uv[i].y()));
  }
  return worst;
}

TEST_F(DefaultView, CameraThatMovedIsPartialWithoutPositionsAfterIt) {
  // From frame 12 the whole picture is shifted by (9, -6) px: the camera moved. Truth: that frame.
  const std::string video = (TempDir() / "moved.avi").string();
  const std::vector<Eigen::Vector2d> uv = WriteChangedClip(*renderer_, *setup_, video, 24, 12, [](cv::Mat& f) {
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 9, 0, 1, -6);
    cv::warpAffine(f.clone(), f, shift, f.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  });
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration);
  ASSERT_EQ(track.rows.size(), 24u);
  EXPECT_TRUE(track.partial);
  EXPECT_TRUE(track.input_problem);
  EXPECT_NE(track.partial_reason.find("changed at frame 12"), std::string::npos) << track.partial_reason;
  EXPECT_NE(track.partial_reason.find("camera moved"), std::string::npos) << track.partial_reason;
  double worst = 0;
  for (int i = 0; i < 24; ++i) {
    const BallObservation& b = track.rows[i].ball;
    if (i >= 12) {
      EXPECT_FALSE(b.found) << "frame " << i << ": a position after the camera moved is invented";
    } else {
      ASSERT_TRUE(b.found) << "frame " << i;
      worst = std::max(worst, std::hypot(b.u - uv[i].x(), b.v - uv[i].y()));
    }
  }
  std::printf("  frames before the move: largest error %.4f px\n", worst);
  EXPECT_LT(worst, 0.04);  // measured: 0.027 px
}

TEST_F(DefaultView, ExposureThatChangedIsPartialAndKeepsPositions) {
  // From frame 10 the exposure is 1.6 times longer (auto-exposure stepped). Truth: that frame,
  // and the renderer's centres (the positions stay measurable).
  const std::string video = (TempDir() / "exposure.avi").string();
  const std::vector<Eigen::Vector2d> uv =
      WriteChangedClip(*renderer_, *setup_, video, 20, 10, [](cv::Mat& f) { f *= 1.6; });
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration);
  ASSERT_EQ(track.rows.size(), 20u);
  EXPECT_TRUE(track.partial);
  EXPECT_TRUE(track.input_problem);
  EXPECT_NE(track.partial_reason.find("exposure changed at frame 10"), std::string::npos) << track.partial_reason;
  ASSERT_EQ(track.exposure_changes.size(), 1u);
  EXPECT_EQ(track.exposure_changes[0], 10);
  const double worst = LargestError(track, uv);
  std::printf("  largest error %.4f px\n", worst);
  EXPECT_LT(worst, 0.07);  // measured: 0.047 px
}

TEST_F(DefaultView, NoiseAfterCopiedFramesIsNotASceneChange) {
  // An encoder at a phone's bit rate copies a still background exactly for the first frames
  // (no residual at all) and re-encodes it, with its noise, at the next key frame. Written here
  // as frames without noise, then with noise of 8 levels from frame 10 (a median residual of
  // 3.6 %, as much as the camera moved by 9 px above gives): the scene itself never changes.
  // Truth: nothing moved but the ball, and the renderer's centres.
  const std::string video = (TempDir() / "copied.avi").string();
  const std::vector<Eigen::Vector2d> uv = WriteChangedClip(*renderer_, *setup_, video, 24, 10, [](cv::Mat&) {}, 0.0, 8.0);
  const TrackResult track = TrackVideo(video, setup_->scene, setup_->calibration);
  ASSERT_EQ(track.rows.size(), 24u);
  EXPECT_FALSE(track.partial) << track.partial_reason;
  const double worst = LargestError(track, uv);
  std::printf("  largest error %.4f px\n", worst);
  EXPECT_LT(worst, 0.1);  // measured: 0.070 px
}

TEST(VisionTrack, SpheroidCleanClip) {
  ClipSetup setup = DefaultClipSetup(1280, 720);
  setup.scene = Scene(Body::Spheroid(0.015875, 0.0254), setup.scene.rails(), setup.scene.rod_radius());
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const Motion motion(setup.scene, 0.97 * *setup.scene.x_eq());
  ClipSettings s;
  s.frames = 12;
  s.release_time = -1.4;
  // measured: 0.028 px, 0.029 mm
  ExpectAccurate(RenderAndTrack(renderer, setup.scene, motion, s, "spheroid.avi").errors, 10, 0.045, 0.045);
}

// A fast ball under a long exposure (issue 10's 360° shutter at 30 fps): steep rails (H = 250 mm,
// D = 20 mm), the 1-inch ball released at x0 = 700 mm and smeared over up to 3 radii by the end
// while it still gains speed. Truth: the renderer's centre at mid-exposure (frame/fps); the blur
// is the average of 32 renders spread evenly over the exposure along the true (accelerated)
// motion, independent of the tracker's smear model. The ball is matte and shaded by a light from
// above (Lambert's law with ambient light, clamped at the terminator: not the quadratic in the
// normal the tracker learns). What is tested is the smear's geometry and timing and the body's
// shading across it: with one limb colour per ray this clip measured 0.39 px RMS (0.07 px for the
// same ball in one flat colour), and before the smear followed the acceleration over the
// exposure (and the fast path gave way at the release) the centre came out 0.2 px ahead of the
// truth on the longest blurs and 0.7 px behind it on the first moving frames.
TEST(VisionTrack, FastBallUnderA360DegreeShutterIsMeasuredAtMidExposure) {
  ClipSetup setup = DefaultClipSetup(1280, 720);
  setup.scene = Scene(Body::Sphere(0.0127), Rails::FromApparatus(1.0, 0.25, 0.02, LConvention::kHorizontal),
                      setup.scene.rod_radius());
  setup.apparatus.body_finish = ClipApparatus::Finish::kMatte;
  // The side view from half its distance: the ball ~25 px in radius, as in the fast POV-Ray clips.
  const Eigen::Vector3d target(0.42, 0, 0.10);
  setup.calibration = SideViewCamera(1280, 720, target.x(), target.z());
  const Eigen::Vector3d eye = CameraCentre(setup.calibration.pose);
  setup.calibration.pose.translation = -setup.calibration.pose.rotation * (target + 0.5 * (eye - target));
  const ClipRenderer renderer(setup.scene, setup.calibration, setup.apparatus);
  const Motion motion(setup.scene, 0.70);
  ClipSettings s;
  s.frames = 30;
  s.release_time = 0.2;
  s.exposure = 1.0 / 30;
  s.blur_samples = 32;
  s.noise_sigma = 1;
  const ClipRun run = RenderAndTrack(renderer, setup.scene, motion, s, "fast360.avi");
  ExpectAccurate(run.errors, 28, 0.055, 0.03);  // measured: 0.035 px, 0.018 mm
  EXPECT_LE(run.errors.max_uv, 0.12);           // measured: 0.078 px
  // The exposure, not given, measured from the smear against the speed.
  ASSERT_TRUE(run.track.measured_exposure.has_value());
  EXPECT_NEAR(*run.track.measured_exposure, 1.0 / 30, 0.002);
}

TEST(VisionTrack, BadInputIsNamed) {
  const ClipSetup setup = DefaultClipSetup(320, 180);
  const std::string text = (TempDir() / "notes.mp4").string();
  std::ofstream(text) << "this is not a video\n";
  ExpectInputError([&] { TrackVideo(text, setup.scene, setup.calibration); }, {"notes.mp4", "not a video"});
  EXPECT_THROW(TrackVideo((TempDir() / "missing.mp4").string(), setup.scene, setup.calibration), InputError);

  // A calibration for another image size.
  const std::string video = (TempDir() / "small.avi").string();
  {
    cv::VideoWriter w(video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30, cv::Size(320, 180));
    for (int i = 0; i < 3; ++i) w.write(cv::Mat(180, 320, CV_8UC3, cv::Scalar(90, 120, 150)));
  }
  const ClipSetup other = DefaultClipSetup(640, 360);
  TrackVideoOptions options;
  options.calibration_name = "scene.json";
  ExpectInputError([&] { TrackVideo(video, other.scene, other.calibration, options); }, {"scene.json", "320x180"});
  // A double cone is not tracked.
  const Scene cone(Body::DoubleCone(0.05, 0.1), setup.scene.rails());
  EXPECT_THROW(BallTracker(cone, setup.calibration), InputError);
  // A readout both given and to be measured.
  TrackerOptions both;
  both.readout = 0.02;
  both.measure_readout = true;
  ExpectInputError([&] { BallTracker(setup.scene, setup.calibration, both); }, {"--readout", "auto"});
  TrackerOptions beyond_one;
  beyond_one.min_report_quality = 1.5;
  ExpectInputError([&] { BallTracker(setup.scene, setup.calibration, beyond_one); }, {"--min-quality", "[0, 1]"});
}

}  // namespace
}  // namespace uphill::testing
