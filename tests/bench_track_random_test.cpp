// The random scenes of `uphill bench track --random` (src/bench/track_random_draw.hpp): a draw is
// a pure function of its seed, down to its encoded pictures, and every drawn quantity lies in the
// range RandomSceneRanges states. Truth: the ranges struct itself, PhoneBitRate for the bit rate,
// uphill::Motion (src/motion) for "coming to rest" (the motion's own events say whether and when
// it rests), and for the encoder the same frames in, decoded by OpenCV.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <unistd.h>

#include "bench/track_random_draw.hpp"
#include "footage/video_encoder.hpp"
#include "motion/motion.hpp"

namespace uphill::bench {
namespace {

constexpr int kSeeds = 300;

TEST(RandomScene, IsAPureFunctionOfItsSeed) {
  for (std::uint64_t seed : {DrawSeed(1, 0), DrawSeed(1, 1), DrawSeed(20261129, 7)}) {
    const RandomScene a = DrawRandomScene(seed), b = DrawRandomScene(seed);
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.Summary(), b.Summary());
    EXPECT_EQ(DescribeFootage(a.condition).dump(), DescribeFootage(b.condition).dump());
  }
  const RandomScene a = DrawRandomScene(DrawSeed(1, 0)), b = DrawRandomScene(DrawSeed(1, 1));
  EXPECT_NE(a.id, b.id);
  EXPECT_NE(DescribeFootage(a.condition).dump(), DescribeFootage(b.condition).dump());
  EXPECT_NE(DrawSeed(1, 0), DrawSeed(2, 0));
}

// The same frames encoded three times at a phone's bit rate give the same pictures: a draw's clip
// must not depend on the encoder's threads (x264's frame threads under a bit rate made every
// encode of a clip differ by a few levels, and a replayed draw then tracked differently).
TEST(RandomScene, ItsClipIsTheSamePicturesOnEveryEncode) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("uphill-encode-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  cv::RNG rng(7);
  cv::Mat table(360, 640, CV_8UC3);
  rng.fill(table, cv::RNG::UNIFORM, 60, 200);  // grain everywhere: the bit rate binds
  std::vector<std::vector<cv::Mat>> runs;
  for (int run = 0; run < 3; ++run) {
    const std::string path = (dir / ("clip" + std::to_string(run) + ".mp4")).string();
    VideoEncoderSettings settings;
    settings.fps = 60;
    VideoEncoder encoder(path, table.size(), settings);
    for (int f = 0; f < 60; ++f) {
      cv::Mat frame = table.clone();
      cv::circle(frame, cv::Point(100 + 6 * f, 180), 30, cv::Scalar(40, 160, 220), cv::FILLED, cv::LINE_AA);
      encoder.Write(frame);
    }
    encoder.Finish();
    cv::VideoCapture capture(path, cv::CAP_FFMPEG);
    ASSERT_TRUE(capture.isOpened()) << path;
    runs.emplace_back();
    for (cv::Mat frame; capture.read(frame);) runs.back().push_back(frame.clone());
    ASSERT_EQ(runs.back().size(), 60u) << path;
  }
  std::filesystem::remove_all(dir);
  for (int run = 1; run < 3; ++run)
    for (int f = 0; f < 60; ++f) EXPECT_EQ(cv::norm(runs[run][f], runs[0][f], cv::NORM_INF), 0) << "encode " << run << ", frame " << f;
}

TEST(RandomScene, EveryDrawnQuantityLiesInItsRange) {
  const RandomSceneRanges r;
  std::set<RandomMotion> motions;
  std::set<RandomSurface> surfaces;
  std::set<int> tables, widths, lights;
  int spheroids = 0, rolling = 0, flicker = 0;
  for (int k = 0; k < kSeeds; ++k) {
    const RandomScene s = DrawRandomScene(DrawSeed(42, k));
    const FootageCondition& c = s.condition;
    SCOPED_TRACE(s.id + ": " + s.Summary());
    if (s.spheroid) {
      ++spheroids;
      EXPECT_TRUE(r.spheroid_a_mm.Holds(s.a_mm));
      EXPECT_TRUE(r.spheroid_b_over_a.Holds(s.b_mm / s.a_mm));
    } else {
      EXPECT_TRUE(r.sphere_radius_mm.Holds(s.a_mm));
      EXPECT_EQ(s.a_mm, s.b_mm);
    }
    EXPECT_NEAR(c.scene.body().across * 1e3, s.a_mm, 1e-9);
    EXPECT_TRUE(r.rod_radius_mm.Holds(s.rod_radius_mm));
    EXPECT_NEAR(c.scene.rod_radius() * 1e3, s.rod_radius_mm, 1e-9);
    EXPECT_TRUE(r.rail_rise_mm.Holds(s.rail_rise_mm));
    EXPECT_TRUE(r.rail_spread_mm.Holds(s.rail_spread_mm));
    EXPECT_GE(s.lights, 1);
    EXPECT_LE(s.lights, 1 + r.max_extra_lights);
    EXPECT_EQ(static_cast<int>(c.look.lamps.size()), s.lights - 1);
    for (const FootageLamp& lamp : c.look.lamps) {
      EXPECT_TRUE(r.lamp_intensity.Holds(lamp.intensity));
      EXPECT_GT(lamp.position.z(), 0.1);  // above the table
    }
    EXPECT_TRUE(r.light_scale.Holds(c.look.light));
    if (s.flicker) {
      ++flicker;
      EXPECT_TRUE(r.flicker_depth.Holds(c.light.flicker_depth));
    }
    EXPECT_NE(std::find(r.resolutions.begin(), r.resolutions.end(), std::array<int, 2>{s.width, s.height}),
              r.resolutions.end());
    EXPECT_EQ(c.camera.camera.width, s.width);
    EXPECT_NE(std::find(r.frame_rates.begin(), r.frame_rates.end(), s.fps), r.frame_rates.end());
    EXPECT_TRUE(r.focal_over_width.Holds(c.camera.camera.fx / s.width));
    ASSERT_EQ(c.camera.camera.distortion.size(), 5u);
    EXPECT_TRUE(r.k1.Holds(c.camera.camera.distortion[0]));
    EXPECT_TRUE(r.k2.Holds(c.camera.camera.distortion[1]));
    EXPECT_TRUE(r.tangential.Holds(c.camera.camera.distortion[2]));
    EXPECT_TRUE(r.tangential.Holds(c.camera.camera.distortion[3]));
    EXPECT_TRUE(r.azimuth_deg.Holds(s.azimuth_deg));
    EXPECT_TRUE(r.elevation_deg.Holds(s.elevation_deg));
    EXPECT_LE(s.body_radius_px, r.body_radius_px.high);  // only ever made smaller, to fit the path
    EXPECT_TRUE(r.vignetting.Holds(c.vignetting));
    EXPECT_GE(c.shutter.exposure, r.shortest_exposure_s - 1e-15);
    EXPECT_LE(c.shutter.exposure, 1 / s.fps + 1e-15);
    if (s.readout_s > 0) {
      ++rolling;
      EXPECT_LE(s.readout_s, std::min(r.readout_ms.high * 1e-3, 0.9 / s.fps) + 1e-15);
    }
    EXPECT_TRUE(r.full_well.Holds(c.sensor.full_well));
    EXPECT_TRUE(r.read_noise.Holds(c.sensor.read_noise));
    EXPECT_EQ(c.codec, VideoCodec::kH264);
    EXPECT_TRUE(
        r.bit_rate_factor.Holds(c.bit_rate / PhoneBitRate(c.codec, cv::Size(s.width, s.height), s.fps)));
    EXPECT_GE(c.frames, 1);
    EXPECT_LE(c.frames, r.max_frames);
    EXPECT_LE(c.frames / s.fps, r.clip_seconds + 1e-9);
    EXPECT_GT(c.x0, c.scene.x_low());
    EXPECT_LT(c.x0, c.scene.x_max());
    const double X = *c.scene.x_eq();
    switch (s.motion) {
      case RandomMotion::kAtRest: EXPECT_GT(c.release_time, 1e3); break;
      case RandomMotion::kRollingDown:
        EXPECT_TRUE(r.down_start_before_x_mm.Holds((X - c.x0) * 1e3));
        EXPECT_TRUE(r.release_s.Holds(c.release_time));
        break;
      case RandomMotion::kRollingUp:
        EXPECT_TRUE(r.up_start_beyond_x_mm.Holds((c.x0 - X) * 1e3));
        EXPECT_TRUE(r.release_s.Holds(c.release_time));
        break;
      case RandomMotion::kComingToRest: {
        EXPECT_TRUE(r.mu.Holds(s.mu));
        EXPECT_EQ(c.motion.mu, s.mu);
        // The truth's own events: pushed toward X, it comes to rest before the clip ends.
        const Motion motion(c.scene, c.x0, c.motion);
        ASSERT_FALSE(motion.events().empty());
        const MotionEvent& last = motion.events().back();
        EXPECT_EQ(last.kind, MotionEventKind::kRest);
        EXPECT_LT(c.release_time + last.t, c.frames / s.fps);
        break;
      }
    }
    motions.insert(s.motion);
    surfaces.insert(s.surface);
    tables.insert(static_cast<int>(s.table));
    widths.insert(s.width);
    lights.insert(s.lights);
  }
  // Every kind is drawn.
  EXPECT_EQ(motions.size(), 4u);
  EXPECT_EQ(surfaces.size(), 7u);
  EXPECT_EQ(tables.size(), 4u);
  EXPECT_EQ(widths.size(), r.resolutions.size());
  EXPECT_EQ(lights.size(), static_cast<size_t>(1 + r.max_extra_lights));
  EXPECT_GT(spheroids, 0);
  EXPECT_GT(rolling, 0);
  EXPECT_GT(flicker, 0);
}

}  // namespace
}  // namespace uphill::bench
