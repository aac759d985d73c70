#include "footage/footage_conditions.hpp"

#include <Eigen/Geometry>
#include <cstdio>

#include "model/input_error.hpp"

namespace uphill {
namespace {

using Eigen::Vector3d;

constexpr double kDegree = 3.14159265358979323846 / 180;

// A phone's camera: fx = fy = 0.9·width, principal point a little off centre, barrel distortion.
CameraIntrinsics PhoneCamera(int width, int height) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 0.9 * width;
  k.cx = (width - 1) / 2.0 + 0.006 * width;
  k.cy = (height - 1) / 2.0 - 0.004 * width;
  k.distortion = {-0.12, 0.06, 7e-4, -4e-4, -0.015};
  return k;
}

FootageCondition Common(const std::string& name, int width, int height, double fps) {
  FootageCondition c;
  c.name = name;
  c.camera.camera = PhoneCamera(width, height);
  c.shutter.fps = fps;
  c.shutter.exposure = 0.5 / fps;  // 180°
  c.shutter.height = height;
  c.sensor.seed = 20261123;
  return c;
}

// The lab family (see the header).
FootageCondition Lab(const std::string& name, int width = 1280, int height = 720, double fps = 30) {
  FootageCondition c = Common(name, width, height, fps);
  c.scene = Scene(Body::Sphere(0.0254), Rails::FromApparatus(1.0, 0.1, 0.15, LConvention::kHorizontal), 0.004);
  c.apparatus.crossbar_x = 1.0;
  c.x0 = 0.25;
  c.release_time = 0.3;
  c.frames = static_cast<int>(1.5 * fps) + 1;
  c.camera.pose = LookAtPose(Vector3d(0.40, -1.08, 0.34), Vector3d(0.42, 0, 0.05));
  return c;
}

// The fast family (see the header).
FootageCondition Fast(const std::string& name, double fps, double shutter_deg) {
  FootageCondition c = Common(name, 1920, 1080, fps);
  c.scene = Scene(Body::Sphere(0.0127), Rails::FromApparatus(1.0, 0.25, 0.02, LConvention::kHorizontal), 0.004);
  c.apparatus.crossbar_x = 1.0;
  c.look.table = TableCover::kCloth;
  c.x0 = 0.70;
  c.release_time = 0.25;
  c.frames = static_cast<int>(std::round(1.0 * fps));
  c.shutter.exposure = shutter_deg / 360 / fps;
  c.camera.pose = LookAtPose(Vector3d(0.37, -0.86, 0.42), Vector3d(0.38, 0, 0.11));
  return c;
}

NamedFootage Track(FootageCondition c, const std::string& description) {
  return {std::move(c), FootageExpectation::kTrack, description};
}

NamedFootage Bad(FootageCondition c, const std::string& description) {
  return {std::move(c), FootageExpectation::kBadInput, description};
}

}  // namespace

std::vector<NamedFootage> RobustnessMatrix() {
  std::vector<NamedFootage> m;
  {
    FootageCondition c = Lab("clean");
    c.sensor.noise = false;
    c.codec = VideoCodec::kFfv1;
    c.shutter.exposure = 1.0 / 500;
    m.push_back(Track(c, "lab 720p30, 1/500 s, no noise, lossless"));
  }
  m.push_back(Track(Lab("baseline"), "lab 720p30 180deg, noise, H.264"));
  {
    FootageCondition c = Lab("h265");
    c.codec = VideoCodec::kH265;
    m.push_back(Track(c, "baseline in H.265"));
  }
  m.push_back(Track(Lab("1080p", 1920, 1080), "baseline at 1920x1080"));
  {
    FootageCondition c = Lab("isoluminant");
    // Turquoise: the grey level of the wood, another hue. Measured on frame 0 (OpenCV's grey of
    // the 8-bit frame): the ball's mean grey 132, the table's around it 134; just inside and just
    // outside the outline 116 and 127 (the ball's own shading), while in colour the ball is
    // (B, G, R) = (158, 156, 74) against (93, 129, 160).
    c.look.body_rgb = Vector3d(0.16, 0.92, 0.95);
    m.push_back(Track(c, "ball as grey as the wood, contrast in colour only"));
  }
  {
    FootageCondition c = Lab("cloth");
    c.look.table = TableCover::kCloth;
    m.push_back(Track(c, "woven cloth table"));
  }
  {
    FootageCondition c = Lab("thin-rails");
    c.scene = Scene(c.scene.body(), c.scene.rails(), 0.0005);
    m.push_back(Track(c, "1 mm wires instead of 8 mm rods"));
  }
  {
    FootageCondition c = Lab("spheroid-band", 1280, 720, 60);
    c.scene = Scene(Body::Spheroid(0.015875, 0.0254), c.scene.rails(), 0.0005);
    c.look.body_rgb = Vector3d(0.80, 0.55, 0.03);  // yellow
    c.look.band_rgb = Vector3d(0.04, 0.05, 0.12);  // a dark blue band
    c.look.band_half_width = 0.004;
    m.push_back(Track(c, "paper's yellow spheroid, painted band, 1 mm wires, 720p60"));
  }
  {
    FootageCondition c = Lab("flicker");
    c.light.flicker_depth = 0.3;
    m.push_back(Track(c, "mains flicker 30% at 100 Hz"));
  }
  {
    FootageCondition c = Lab("ae-drift");
    c.light.drift_depth = 0.15;
    c.light.drift_period = 1.5;
    m.push_back(Track(c, "auto-exposure drift +-15% over 1.5 s"));
  }
  {
    FootageCondition c = Lab("partly-out");
    c.camera.pose = LookAtPose(Vector3d(0.83, -1.08, 0.34), Vector3d(0.85, 0, 0.05));
    m.push_back(Track(c, "ball rolls out of the frame's left edge"));
  }
  m.push_back(Track(Fast("fast-180-30", 30, 180), "fast ball 1080p30 180deg, cloth"));
  m.push_back(Track(Fast("fast-360-30", 30, 360), "fast ball 1080p30 360deg (blur to 3 R), cloth"));
  m.push_back(Track(Fast("fast-180-60", 60, 180), "fast ball 1080p60 180deg, cloth"));
  m.push_back(Track(Fast("fast-360-60", 60, 360), "fast ball 1080p60 360deg, cloth"));
  {
    FootageCondition c = Fast("rolling-shutter", 30, 180);
    c.shutter.readout = 0.025;
    m.push_back(Track(c, "fast 1080p30 180deg, rolling shutter 25 ms"));
  }
  {
    FootageCondition c = Lab("bad-no-body");
    c.events.body_never_visible = true;
    m.push_back(Bad(c, "the body is never in the picture"));
  }
  {
    FootageCondition c = Lab("bad-camera-moved");
    c.events.camera_moves_at = 27;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.6 * kDegree, Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
    c.events.moved_pose.rotation = turn * c.camera.pose.rotation;
    c.events.moved_pose.translation = turn * c.camera.pose.translation + Vector3d(0.004, -0.002, 0.001);
    m.push_back(Bad(c, "camera bumped at 0.9 s"));
  }
  {
    FootageCondition c = Lab("bad-exposure-change");
    c.events.exposure_changes_at = 27;
    c.events.changed_exposure = 1.0 / 250;
    c.events.changed_gain = 1.6;
    m.push_back(Bad(c, "exposure 1/60 s -> 1/250 s and gain x1.6 at 0.9 s"));
  }
  return m;
}

NamedFootage FootageByName(const std::string& name) {
  if (name == "tiny") {
    // Closer than the lab camera, so that the ball keeps a radius of ~16 px at 320 px wide;
    // marks every 100 mm give the scene calibration its points.
    FootageCondition c = Lab("tiny", 320, 180, 30);
    c.frames = 10;
    c.release_time = 0.05;
    c.x0 = 0.20;
    c.boards = 10;
    c.apparatus.marks = {0.1, 0.2, 0.3};
    c.camera.pose = LookAtPose(Vector3d(0.19, -0.44, 0.17), Vector3d(0.19, 0, 0.035));
    return Track(c, "lab baseline at 320x180, 10 frames (tests)");
  }
  std::string names;
  for (NamedFootage& f : RobustnessMatrix()) {
    if (f.condition.name == name) return f;
    names += (names.empty() ? "" : ", ") + f.condition.name;
  }
  throw InputError("condition", "unknown: '" + name + "' (known: tiny, " + names + ")");
}

std::string FootageSceneFlags(const FootageCondition& c) {
  const Body& body = c.scene.body();
  const double L = c.apparatus.crossbar_x;
  char text[320];
  if (body.kind == BodyKind::kSphere)
    std::snprintf(text, sizeof text, "--body sphere --R %.9gmm", body.across * 1e3);
  else
    std::snprintf(text, sizeof text, "--body spheroid --a %.9gmm --b %.9gmm", body.across * 1e3, body.along * 1e3);
  std::string out = text;
  std::snprintf(text, sizeof text, " --L %.9gmm --H %.9gmm --D %.9gmm --rod-diameter %.9gmm", L * 1e3,
                L * c.scene.rails().tan_theta * 1e3, 2 * L * c.scene.rails().tan_half_alpha * 1e3,
                2 * c.scene.rod_radius() * 1e3);
  return out + text;
}

}  // namespace uphill
