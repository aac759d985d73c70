#include "bench/track_random_draw.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "footage/video_encoder.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"

namespace uphill::bench {
namespace {

using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180;

// Doubles in [0, 1) from the top 53 bits: the same numbers with every standard library.
class Draws {
 public:
  explicit Draws(std::uint64_t seed) : engine_(seed) {}
  double Unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double In(const DrawRange& r) { return r.low + (r.high - r.low) * Unit(); }
  double LogIn(double low, double high) { return low * std::exp(std::log(high / low) * Unit()); }
  int Index(size_t n) { return static_cast<int>(std::min<double>(n - 1, std::floor(Unit() * n))); }
  bool Chance(double p) { return Unit() < p; }

 private:
  std::mt19937_64 engine_;
};

std::string Fixed(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

Vector3d Colour(Draws& d) {
  // A saturated or a grey paint, linear reflectance 0.02-0.7.
  Vector3d c(d.Unit(), d.Unit(), d.Unit());
  return (0.02 + 0.68 * d.Unit()) * c / std::max(1e-3, c.maxCoeff());
}

// The first stop (turning point or rest) of a motion, or +∞.
double FirstStop(const Motion& m) {
  for (const MotionEvent& e : m.events())
    if (e.kind == MotionEventKind::kTurningPoint || e.kind == MotionEventKind::kRest) return e.x;
  return INFINITY;
}

// The push v0 toward X from x0 that makes the body stop first at x_stop (bisection: the stop
// moves out monotonically with the push), or nullopt when none does below 3 m/s.
std::optional<double> PushToStopAt(const Scene& scene, double x0, double x_stop, const MotionOptions& base) {
  double low = 0, high = 3;
  MotionOptions o = base;
  o.v0 = high;
  if (FirstStop(Motion(scene, x0, o)) < x_stop) return std::nullopt;
  for (int i = 0; i < 50; ++i) {
    o.v0 = 0.5 * (low + high);
    (FirstStop(Motion(scene, x0, o)) < x_stop ? low : high) = o.v0;
  }
  return high;
}

// One attempt; false when this set of numbers makes no drawable scene (the caller draws again).
bool TryDraw(Draws& d, const RandomSceneRanges& r, RandomScene& s) {
  // Body and rails.
  s.spheroid = d.Chance(r.spheroid_share);
  s.a_mm = s.spheroid ? d.In(r.spheroid_a_mm) : d.In(r.sphere_radius_mm);
  s.b_mm = s.spheroid ? s.a_mm * d.In(r.spheroid_b_over_a) : s.a_mm;
  s.rail_rise_mm = d.In(r.rail_rise_mm);
  s.rail_spread_mm = d.In(r.rail_spread_mm);
  s.rod_radius_mm = d.In(r.rod_radius_mm);
  if (s.rod_radius_mm >= 0.8 * s.a_mm) return false;
  FootageCondition& c = s.condition;
  const Body body = s.spheroid ? Body::Spheroid(s.a_mm * 1e-3, s.b_mm * 1e-3) : Body::Sphere(s.a_mm * 1e-3);
  c.scene = Scene(body, Rails::FromApparatus(1.0, s.rail_rise_mm * 1e-3, s.rail_spread_mm * 1e-3,
                                             LConvention::kHorizontal),
                  s.rod_radius_mm * 1e-3);
  c.apparatus.crossbar_x = 1.0;
  const std::optional<double> X = c.scene.x_eq();
  if (!X || *X < 0.2 || *X > 0.9) return false;

  // Surface, lights, table, rods.
  s.surface = static_cast<RandomSurface>(d.Index(7));
  FootageLook& look = c.look;
  look.body_rgb = Colour(d);
  look.band_rgb = Colour(d);
  look.finish = BodyFinish::kSatin;
  switch (s.surface) {
    case RandomSurface::kMatte: look.finish = BodyFinish::kMatte; break;
    case RandomSurface::kTwoTone: look.pattern = BodyPattern::kTwoTone; break;
    case RandomSurface::kBand: look.band_half_width = s.a_mm * 1e-3 * d.In(r.band_half_width_over_a); break;
    case RandomSurface::kStripes:
      look.pattern = BodyPattern::kStripes;
      look.pattern_scale = s.a_mm * 1e-3 * d.In(r.stripe_period_over_a);
      break;
    case RandomSurface::kDots:
      look.pattern = BodyPattern::kDots;
      look.pattern_scale = s.a_mm * 1e-3 * d.In(r.dot_scale_over_a);
      break;
    case RandomSurface::kGlossy: look.finish = BodyFinish::kGlossy; break;
    case RandomSurface::kChrome: look.finish = BodyFinish::kChrome; break;
  }
  look.pattern_turn = Vector3d(360 * d.Unit(), 360 * d.Unit(), 360 * d.Unit());
  look.light = d.In(r.light_scale);
  const int lamps = d.Index(r.max_extra_lights + 1);
  for (int k = 0; k < lamps; ++k) {
    const double az = 2 * kPi * d.Unit(), el = (15 + 70 * d.Unit()) * kDegree, dist = 0.8 + 1.2 * d.Unit();
    look.lamps.push_back({Vector3d(0.5 + dist * std::cos(el) * std::cos(az), dist * std::cos(el) * std::sin(az),
                                   dist * std::sin(el)),
                          d.In(r.lamp_intensity)});
  }
  s.lights = 1 + lamps;
  s.table = static_cast<TableCover>(d.Index(4));
  look.table = s.table;
  if (d.Chance(0.5)) look.rod_rgb = Colour(d);
  s.flicker = d.Chance(r.flicker_share);
  if (s.flicker) {
    c.light.flicker_depth = d.In(r.flicker_depth);
    c.light.flicker_hz = d.Chance(0.5) ? 100 : 120;
  }

  // Camera settings.
  const std::array<int, 2> size = r.resolutions[d.Index(r.resolutions.size())];
  s.width = size[0], s.height = size[1];
  s.fps = r.frame_rates[d.Index(r.frame_rates.size())];
  s.exposure_s = std::max(r.shortest_exposure_s,
                          d.LogIn(r.shutter_angle_deg.low, r.shutter_angle_deg.high) / 360 / s.fps);
  s.exposure_s = std::min(s.exposure_s, 1 / s.fps);
  s.readout_s = d.Chance(r.rolling_share) ? std::min(d.In(r.readout_ms) * 1e-3, 0.9 / s.fps) : 0;
  c.frames = std::min(r.max_frames, static_cast<int>(std::round(r.clip_seconds * s.fps)));
  c.shutter.fps = s.fps;
  c.shutter.exposure = s.exposure_s;
  c.shutter.readout = s.readout_s;
  c.shutter.height = s.height;
  c.sensor.full_well = d.In(r.full_well);
  c.sensor.read_noise = d.In(r.read_noise);
  c.sensor.seed = s.seed;
  c.vignetting = d.In(r.vignetting);
  c.codec = VideoCodec::kH264;
  c.bit_rate = PhoneBitRate(c.codec, cv::Size(s.width, s.height), s.fps) * d.In(r.bit_rate_factor);
  c.boards = 0;  // tracked with the true camera: the calibration's error is another benchmark's

  // Motion (uphill::Motion: the truth).
  s.motion = static_cast<RandomMotion>(d.Index(4));
  const double duration = c.frames / s.fps;
  c.release_time = d.In(r.release_s);
  MotionOptions m;
  switch (s.motion) {
    case RandomMotion::kAtRest:
      c.x0 = *X - 1e-3 * d.In(r.down_start_before_x_mm);
      c.release_time = 1e6;  // never released within the clip
      break;
    case RandomMotion::kRollingDown: c.x0 = *X - 1e-3 * d.In(r.down_start_before_x_mm); break;
    case RandomMotion::kRollingUp: c.x0 = *X + 1e-3 * d.In(r.up_start_beyond_x_mm); break;
    case RandomMotion::kComingToRest: {
      s.mu = d.In(r.mu);
      m.mu = s.mu;
      m.method = MotionMethod::kOde;
      const std::optional<RestBand> band = c.scene.Rest(s.mu);
      if (!band) return false;
      const double stop = band->low + (std::min(*X, band->high) - band->low) * d.Unit();
      c.x0 = stop - 1e-3 * d.In(r.rest_approach_mm);
      if (c.x0 <= c.scene.x_low() + 0.02) return false;
      const std::optional<double> v0 = PushToStopAt(c.scene, c.x0, stop, m);
      if (!v0) return false;
      s.v0 = m.v0 = *v0;
      c.release_time = 0.3 * c.release_time;  // pushed early: the stop falls within the clip
      const Motion pushed(c.scene, c.x0, m);
      if (pushed.events().empty() || pushed.events().back().kind != MotionEventKind::kRest ||
          c.release_time + pushed.events().back().t >= duration)
        return false;
      break;
    }
  }
  if (c.x0 <= c.scene.x_low() + 0.02 || c.x0 >= c.scene.x_max()) return false;
  c.motion = m;

  // Where the body goes within the clip: the camera frames it.
  const Motion motion(c.scene, c.x0, m);
  double x_low = c.x0, x_high = c.x0;
  for (int k = 0; k <= 50; ++k) {
    const double t = std::max(0.0, duration * k / 50 - c.release_time);
    if (t > motion.end_time()) break;
    const double x = motion.At(t).x;
    x_low = std::min(x_low, x), x_high = std::max(x_high, x);
  }
  const double x_mid = 0.5 * (x_low + x_high);
  const Vector3d target(x_mid, 0, c.scene.At(x_mid).z);
  s.focal_over_width = d.In(r.focal_over_width);
  CameraIntrinsics& k = c.camera.camera;
  k.width = s.width, k.height = s.height;
  k.fx = k.fy = s.focal_over_width * s.width;
  k.cx = (s.width - 1) / 2.0 + 0.01 * s.width * (d.Unit() - 0.5);
  k.cy = (s.height - 1) / 2.0 + 0.01 * s.width * (d.Unit() - 0.5);
  k.distortion = {d.In(r.k1), d.In(r.k2), d.In(r.tangential), d.In(r.tangential), 0};
  // The body's size in pixels, made smaller when its path would not fit in 70 % of the width.
  const double R = s.a_mm * 1e-3;
  s.body_radius_px = d.In(r.body_radius_px);
  double distance = k.fx * R / s.body_radius_px;
  distance = std::max(distance, k.fx * (x_high - x_low + 4 * R) / (0.7 * s.width));
  s.body_radius_px = k.fx * R / distance;
  s.azimuth_deg = d.In(r.azimuth_deg);
  s.elevation_deg = d.In(r.elevation_deg);
  const double az = s.azimuth_deg * kDegree, el = s.elevation_deg * kDegree;
  const Vector3d eye = target + distance * Vector3d(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el),
                                                    std::sin(el));
  if (eye.z() < 0.05) return false;
  c.camera.pose = LookAtPose(eye, target);
  c.povray_processes = 1;
  c.povray.threads = 1;
  c.max_subframes = 32;  // bounds a long smear's cost; max_step_px stays 1 up to it
  return true;
}

}  // namespace

const char* RandomMotionName(RandomMotion motion) {
  switch (motion) {
    case RandomMotion::kAtRest: return "at rest";
    case RandomMotion::kRollingDown: return "rolling down";
    case RandomMotion::kRollingUp: return "rolling up";
    case RandomMotion::kComingToRest: return "coming to rest";
  }
  return "?";
}

const char* RandomSurfaceName(RandomSurface surface) {
  switch (surface) {
    case RandomSurface::kMatte: return "matte";
    case RandomSurface::kTwoTone: return "two-tone";
    case RandomSurface::kBand: return "band";
    case RandomSurface::kStripes: return "stripes";
    case RandomSurface::kDots: return "dots";
    case RandomSurface::kGlossy: return "glossy";
    case RandomSurface::kChrome: return "chrome";
  }
  return "?";
}

std::string RandomScene::Summary() const {
  static const char* const kTables[] = {"wood", "cloth", "paper", "tiles"};
  std::string out = spheroid ? Fixed("spheroid a %.1f", a_mm) + Fixed(" b %.1f mm", b_mm) : Fixed("sphere R %.1f mm", a_mm);
  out += std::string(", ") + RandomSurfaceName(surface) + ", " + std::to_string(lights) + " light" +
         (lights > 1 ? "s" : "") + (flicker ? " flicker" : "") + ", " + kTables[static_cast<int>(table)] +
         Fixed(", rod %.1f mm", rod_radius_mm) + (condition.look.rod_rgb ? " painted" : " steel") + ", " +
         std::to_string(width) + "x" + std::to_string(height) + Fixed(" %.0f fps", fps) +
         Fixed(", 1/%.0f s", 1 / exposure_s) + (readout_s > 0 ? Fixed(" rolling %.0f ms", readout_s * 1e3) : "") +
         ", " + RandomMotionName(motion) + (mu > 0 ? Fixed(" mu %.3f", mu) : "");
  return out;
}

std::uint64_t DrawSeed(std::uint64_t run_seed, int k) {
  std::uint64_t z = run_seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(k + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

RandomScene DrawRandomScene(std::uint64_t seed, const RandomSceneRanges& ranges) {
  Draws draws(seed);
  for (int attempt = 0; attempt < 100; ++attempt) {
    RandomScene s;
    s.seed = seed;
    char id[20];
    std::snprintf(id, sizeof id, "%08llx", static_cast<unsigned long long>(seed & 0xffffffffull));
    s.id = id;
    s.condition.name = "random-" + s.id;
    try {
      if (TryDraw(draws, ranges, s)) return s;
    } catch (const InputError&) {
      // A combination the model does not take (a body that cannot rest on these rails): draw again.
    }
  }
  throw std::runtime_error("no drawable random scene for seed " + std::to_string(seed));
}

}  // namespace uphill::bench
