// The random scenes of `uphill bench track --random N`: each draw is a short POV-Ray clip
// (footage/footage_clip.hpp) whose body, surface, lights, table, rods, camera, shutter, codec and
// motion are drawn at random within RandomSceneRanges. A draw is a pure function of its seed
// (DrawRandomScene): the same seed gives the same scene on every run and machine, so a draw that
// shows a problem can be rendered and looked at again.
//
// The random numbers: std::mt19937_64 seeded with the draw's seed, turned into doubles by taking
// its top 53 bits (not std::uniform_real_distribution, whose algorithm the standard leaves to the
// library). Draw k of a run with seed S has the seed DrawSeed(S, k) (SplitMix64 of S and k), so
// draws are independent and any one can be redrawn alone.
//
// The truth: the body moves as uphill::Motion (src/motion) integrates it from the drawn x0, v0
// and μ; the renderer poses the body by it and writes the projected centre per frame. The
// tracker under test shares none of this code.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "footage/footage_clip.hpp"

namespace uphill::bench {

// A closed interval [low, high] of a drawn quantity.
struct DrawRange {
  double low = 0, high = 0;
  bool Holds(double v) const { return v >= low && v <= high; }
};

enum class RandomMotion { kAtRest, kRollingDown, kRollingUp, kComingToRest };
// "at rest", "rolling down" (toward O), "rolling up" (away from O), "coming to rest" (μ).
const char* RandomMotionName(RandomMotion motion);

enum class RandomSurface { kMatte, kTwoTone, kBand, kStripes, kDots, kGlossy, kChrome };
const char* RandomSurfaceName(RandomSurface surface);

// Every drawn quantity's range, each with why it is so. Uniform within a range unless said.
struct RandomSceneRanges {
  // The body: a sphere or the paper's kind of spheroid. No double cone: POV-Ray's scene has none,
  // and the model has no double cone on round rods (model/scene.hpp).
  double spheroid_share = 0.35;
  DrawRange sphere_radius_mm{10, 30};     // a marble to a billiard ball
  DrawRange spheroid_a_mm{10, 22};        // semi-axis across the rails (x, z)
  DrawRange spheroid_b_over_a{1.1, 1.8};  // along the rolling axis: a rugby ball, not a disc
  // The rails: L = 1 m (horizontal), rising by H and spreading by D to the crossbar.
  DrawRange rail_rise_mm{60, 200};
  DrawRange rail_spread_mm{100, 200};
  DrawRange rod_radius_mm{1, 10};  // a wire to a thick rod (the body's radius stays larger)
  // The surface: one of RandomSurface, all equally likely.
  DrawRange band_half_width_over_a{0.15, 0.45};
  DrawRange stripe_period_over_a{0.25, 0.8};
  DrawRange dot_scale_over_a{0.15, 0.4};
  // Lights: the soft box (whose shadow the renderer follows) and 0-2 shadowless lamps anywhere
  // above the table; mains flicker sometimes.
  int max_extra_lights = 2;
  DrawRange lamp_intensity{0.1, 0.45};
  DrawRange light_scale{0.6, 1.3};
  double flicker_share = 0.2;
  DrawRange flicker_depth{0.05, 0.3};
  // The camera: a phone's frame sizes (no 4K: a draw must stay under a minute of ray tracing),
  // its frame rates, its lens.
  std::vector<std::array<int, 2>> resolutions = {{640, 360}, {960, 540}, {1280, 720}, {1920, 1080}};
  std::vector<double> frame_rates = {30, 60, 120, 240};
  DrawRange focal_over_width{0.7, 1.2};  // fx / width: wide to normal lens
  DrawRange k1{-0.2, 0.05};
  DrawRange k2{-0.05, 0.1};
  DrawRange tangential{-1e-3, 1e-3};      // p1, p2
  DrawRange body_radius_px{12, 40};       // the body's size on the sensor, before the span check
  DrawRange azimuth_deg{-35, 35};         // about z, 0: square to the rails
  DrawRange elevation_deg{5, 40};         // above the body's plane
  DrawRange vignetting{0.1, 0.6};
  // The exposure: a shutter angle, log-uniform, never shorter than 1/2000 s.
  DrawRange shutter_angle_deg{5, 360};
  double shortest_exposure_s = 1.0 / 2000;
  double rolling_share = 0.3;
  DrawRange readout_ms{8, 33};  // capped at 0.9 frame times
  // Sensor and codec: H.264 at a phone's bit rate times a factor.
  DrawRange full_well{2000, 12000};
  DrawRange read_noise{1.5, 6};
  DrawRange bit_rate_factor{0.5, 1.5};
  // The motion: one of RandomMotion, all equally likely; about 1 s of it, at most max_frames.
  double clip_seconds = 1.0;
  int max_frames = 40;
  DrawRange release_s{0.05, 0.3};
  DrawRange down_start_before_x_mm{10, 150};  // rolling down: x0 = X − this
  DrawRange up_start_beyond_x_mm{2, 40};      // rolling up: x0 = X + this (then it may fall off)
  DrawRange mu{0.003, 0.03};                  // coming to rest: rolling resistance
  DrawRange rest_approach_mm{20, 80};         // ... pushed toward X from this far before its stop
};

// One draw: its seed and id, what was drawn (for the table and the tests), and the condition
// the renderer takes.
struct RandomScene {
  std::uint64_t seed = 0;
  std::string id;  // 8 hex digits of the seed
  bool spheroid = false;
  double a_mm = 0, b_mm = 0;  // semi-axes (a sphere: a = b = R)
  double rod_radius_mm = 0, rail_rise_mm = 0, rail_spread_mm = 0;
  RandomSurface surface = RandomSurface::kMatte;
  int lights = 1;  // the soft box and the lamps
  bool flicker = false;
  TableCover table = TableCover::kWood;
  int width = 0, height = 0;
  double fps = 0, exposure_s = 0, readout_s = 0;
  double focal_over_width = 0, body_radius_px = 0, azimuth_deg = 0, elevation_deg = 0;
  RandomMotion motion = RandomMotion::kAtRest;
  double mu = 0, v0 = 0;  // m/s
  FootageCondition condition;

  std::string Summary() const;  // one line: body, surface, lights, table, rod, res, fps, shutter, motion
};

// The seed of draw k of a run with seed S (SplitMix64).
std::uint64_t DrawSeed(std::uint64_t run_seed, int k);

// The scene of a seed. Pure: no clock, no files. Throws std::runtime_error only if no drawable
// scene turns up in 100 tries (the ranges above always give one).
RandomScene DrawRandomScene(std::uint64_t seed, const RandomSceneRanges& ranges = {});

}  // namespace uphill::bench
