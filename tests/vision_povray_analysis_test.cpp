// The uncertainty of `uphill analyse-track` on footage the tracker was not tuned on: small
// POV-Ray clips (src/footage/footage_clip.hpp) of a ball released from rest, tracked by
// `uphill track` with the renderer's camera, analysed by `uphill analyse-track`.
//
// Where the truth comes from: the renderer's own parameters: the release position x0 and time t0
// of the rendered motion, and g = 9.80665 m/s² of the uphill::Motion that placed the body in
// each sub-frame (no friction, so the effective g is g). The tracker's error on these clips is
// mostly systematic (edge bias varying along the path and with the speed), which the stated
// uncertainties must cover: |fitted − truth| ≤ 3 u for x0, t0 and g.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "footage/footage_clip.hpp"
#include "footage/footage_conditions.hpp"
#include "footage/povray_render.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

struct Clip {
  double x0, release_time;
  unsigned seed;
};

// The tests' tiny lab clip (320 × 180, 30 frames/s, H.264, sensor noise, a 180° shutter), made
// long enough to see the motion: 26 frames, released from rest after a few of them.
FootageCondition TinyRelease(const Clip& clip) {
  FootageCondition c = FootageByName("tiny").condition;
  c.name = "tiny-release";
  c.frames = 26;
  c.x0 = clip.x0;
  c.release_time = clip.release_time;
  c.sensor.seed = clip.seed;
  c.boards = 0;  // the renderer's camera is used: the error studied is the tracker's
  return c;
}

TEST(PovrayAnalysis, FittedReleaseAndGLieWithinThreeUncertaintiesOfTheRenderersTruth) {
  if (!PovrayAvailable()) FAIL() << "povray is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fs::temp_directory_path() / ("uphill-povray-analysis-" + std::to_string(getpid()));
  fs::create_directories(dir);
  // Two clips (each ~40 s of CPU to render, cached for reruns): different releases and noise.
  const Clip clips[] = {{0.20, 0.20, 11}, {0.17, 0.12, 12}};
  int fitted = 0;
  for (const Clip& clip : clips) {
    const FootageCondition c = TinyRelease(clip);
    // Cached like the benchmark's clips (the key covers every setting): a rerun does not render.
    const FootageFiles files = RenderFootage(c, FootageCacheRoot());
    const std::string track = (dir / ("track-" + std::to_string(clip.seed) + ".csv")).string();
    auto r = RunUphill("track '" + files.video + "' --camera '" + files.camera_truth + "' --scene '" +
                       files.scene_truth + "' " + FootageSceneFlags(c) + " -o '" + track + "'");
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    r = RunUphill("analyse-track '" + track + "' " + FootageSceneFlags(c) + " --u-x 0.1mm --json");
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const nlohmann::json& fit = j["fit"];
    ASSERT_TRUE(fit["available"].get<bool>()) << fit.dump(1);
    ++fitted;
    const double truth[3] = {c.x0, c.release_time, 9.80665};
    const char* names[3] = {"x0", "t0", "g"};
    std::printf("clip x0 = %.0f mm, t0 = %.2f s, seed %u: %zu frames fitted, RMS residual %.3f mm, lag-1 %.2f\n",
                c.x0 * 1e3, c.release_time, clip.seed, fit["frames"].size(), fit["rms_residual"].get<double>() * 1e3,
                fit["residual_lag1"].get<double>());
    for (int k = 0; k < 3; ++k) {
      const nlohmann::json& p = fit["parameters"][names[k]];
      const double value = p["value"], u = p["u"], se_scaled = p["se_scaled"];
      const double pull = (value - truth[k]) / u;
      std::printf("  %-2s %.7g - truth = %+.3g, u = %.3g (statistical %.3g, systematic %.3g; se_scaled %.3g): pull %+.2f\n",
                  names[k], value, value - truth[k], u, p["se_statistical"].get<double>(),
                  p["se_systematic"].get<double>(), se_scaled, pull);
      EXPECT_LE(std::abs(pull), 3.0) << names[k] << ", clip seed " << clip.seed;
    }
    // Still a measurement: the default systematic floor (calibrated on random ray-traced scenes)
    // is conservative on these low-resolution clips, where the tracker is better in pixels.
    // Measured: pulls -0.29, +0.40, +0.32 and -0.12, +0.31, +0.17 (x0, t0, g), with
    // u(x0) = 0.11 mm, u(t0) = 1.0-1.3 ms, u(g) = 0.029-0.040 m/s²; on random ray-traced
    // scenes the pulls' RMS is 0.7-0.9 (docs/analyse-track.md, "Accuracy").
    EXPECT_LT(fit["parameters"]["x0"]["u"].get<double>(), 0.3e-3);
    EXPECT_LT(fit["parameters"]["t0"]["u"].get<double>(), 5e-3);
    EXPECT_LT(fit["parameters"]["g"]["u"].get<double>(), 0.015 * 9.80665);
  }
  ASSERT_EQ(fitted, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
