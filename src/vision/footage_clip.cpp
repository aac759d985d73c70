#include "vision/footage_clip.hpp"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>
#include <atomic>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/json_file.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "motion/motion.hpp"
#include "internal/content_key.hpp"
#include "vision/lens_remap.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2d;
using Eigen::Vector3d;
using ordered_json = nlohmann::ordered_json;

// A digest of the generator's code (src/vision/CMakeLists.txt): what the same condition's pixels
// and truth are depends on it, so it is part of every cache key.
constexpr const char* kGeneratorDigest = UPHILL_FOOTAGE_GENERATOR_DIGEST;
constexpr double kInf = std::numeric_limits<double>::infinity();

ordered_json DescribeCamera(const CameraIntrinsics& c) {
  return {{"width_px", c.width}, {"height_px", c.height}, {"fx_px", c.fx}, {"fy_px", c.fy},
          {"cx_px", c.cx},       {"cy_px", c.cy},         {"distortion", c.distortion}};
}

ordered_json DescribePose(const CameraPose& p) {
  std::vector<double> r(p.rotation.data(), p.rotation.data() + 9);
  return {{"rotation_colmajor", r}, {"translation_m", {p.translation.x(), p.translation.y(), p.translation.z()}}};
}

ordered_json DescribeSensor(const SensorModel& s, double gain, double vignetting) {
  return {{"full_well_e", s.full_well}, {"read_noise_e", s.read_noise}, {"seed", s.seed},
          {"noise", s.noise},           {"gain", gain},                 {"vignetting", vignetting}};
}

ordered_json DescribeBoards(const FootageCondition& c) {
  return {{"generator", kGeneratorDigest},
          {"camera", DescribeCamera(c.camera.camera)},
          {"sensor", DescribeSensor(c.sensor, c.gain, c.vignetting)},
          {"boards", c.boards},
          {"target", {{"cols", c.board_target.cols}, {"rows", c.board_target.rows}, {"square_m", c.board_target.square}}},
          {"povray", {{"aa", c.povray.antialias_threshold}, {"depth", c.povray.antialias_depth}}}};
}

// Smallest t > 0 at which the ray o + t·d (d unit) meets the cylinder of radius r about the
// segment p0 + s·e, s ∈ [0, length] (e unit); ∞ if none.
double RayCylinder(const Vector3d& o, const Vector3d& d, const Vector3d& p0, const Vector3d& e, double r,
                   double length) {
  const Vector3d w = o - p0;
  const Vector3d dp = d - d.dot(e) * e, wp = w - w.dot(e) * e;
  const double a = dp.squaredNorm(), b = wp.dot(dp), c = wp.squaredNorm() - r * r;
  const double disc = b * b - a * c;
  if (a <= 0 || disc < 0) return kInf;
  for (double t : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a}) {
    if (t <= 0) continue;
    const double s = (w + t * d).dot(e);
    if (s >= 0 && s <= length) return t;
  }
  return kInf;
}

struct Cylinder {
  Vector3d p0, e;
  double r, length;
};

// The solid parts of the apparatus that can hide the body: rods, crossbar, posts.
std::vector<Cylinder> Occluders(const Scene& scene, const FootageApparatus& a) {
  const double T = scene.rails().tan_half_alpha, B = scene.rails().tan_theta;
  const double x_end = a.crossbar_x + a.rail_overhang;
  std::vector<Cylinder> out;
  for (int side : {-1, 1}) {
    const Vector3d end(x_end, side * x_end * T, x_end * B);
    out.push_back({Vector3d::Zero(), end.normalized(), scene.rod_radius(), end.norm()});
  }
  const double L = a.crossbar_x;
  const double zc = L * B - scene.rod_radius() - a.crossbar_radius;
  const double half = L * T + 0.05;
  out.push_back({Vector3d(L, -half, zc), Vector3d::UnitY(), a.crossbar_radius, 2 * half});
  for (int side : {-1, 1})
    out.push_back({Vector3d(L, side * L * T, a.table_z), Vector3d::UnitZ(), a.post_radius, zc - a.table_z});
  return out;
}

// Ray parameter of the body's surface (centre c, semi-axes a in x and z, b in y), or ∞.
double RayBody(const Vector3d& o, const Vector3d& d, const Vector3d& c, double a, double b) {
  const double s = a / b;  // scaling y by a/b turns the body into a sphere of radius a
  const Vector3d os(o.x() - c.x(), s * (o.y() - c.y()), o.z() - c.z());
  const Vector3d ds(d.x(), s * d.y(), d.z());
  const double qa = ds.squaredNorm(), qb = os.dot(ds), qc = os.squaredNorm() - a * a;
  const double disc = qb * qb - qa * qc;
  if (disc < 0) return kInf;
  const double t = (-qb - std::sqrt(disc)) / qa;
  return t > 0 ? t : kInf;
}

// Raw pixels of apparatus points; a point outside the camera's field of view is first moved
// toward the axis to just outside it (radius max_radius of its ray), so that the distortion
// polynomial, which folds far-off rays back into the image, cannot bring it in.
std::vector<Vector2d> ProjectOrOutside(const CameraIntrinsics& camera, const CameraPose& pose,
                                       const std::vector<Vector3d>& points, double max_radius) {
  std::vector<Vector3d> in_camera;
  for (const Vector3d& p : points) {
    Vector3d q = pose.rotation * p + pose.translation;
    const double z = std::max(q.z(), 1e-9);
    Vector2d n(q.x() / z, q.y() / z);
    if (q.z() <= 0) n = n.normalized() * 1e3;
    if (n.norm() > 1.05 * max_radius) n *= 1.05 * max_radius / n.norm();
    in_camera.emplace_back(n.x(), n.y(), 1.0);
  }
  return ProjectApparatusPoints(camera, CameraPose{}, in_camera);
}

// One POV-Ray run as counted by PlanFootage.
struct PovrayWork {
  int subframes = 0;
  double pixels = 0;
  bool cached = false;
};

class FootageRenderer {
 public:
  // work: a private folder for POV-Ray's files; pictures: the shared cache of POV-Ray renders.
  FootageRenderer(const FootageCondition& c, const fs::path& work, const fs::path& pictures)
      : c_(c), work_(work), pictures_(pictures), lens_(c.camera.camera), motion_(c.scene, c.x0) {
    timing_ = c.shutter;
    timing_.height = c.camera.camera.height;
    vignetting_ = lens_.Vignetting(c.vignetting);
    occluders_ = Occluders(c.scene, c.apparatus);
    poses_.push_back(c.camera.pose);
    if (c.events.camera_moves_at >= 0) poses_.push_back(c.events.moved_pose);
    a_ = c.scene.body().across;
    b_ = c.scene.body().along;
  }

  const LensRemap& lens() const { return lens_; }

  int PoseIndex(int frame) const {
    return c_.events.camera_moves_at >= 0 && frame >= c_.events.camera_moves_at ? 1 : 0;
  }
  double Exposure(int frame) const {
    return c_.events.exposure_changes_at >= 0 && frame >= c_.events.exposure_changes_at ? c_.events.changed_exposure
                                                                                         : timing_.exposure;
  }
  double Gain(int frame) const {
    return c_.gain *
           (c_.events.exposure_changes_at >= 0 && frame >= c_.events.exposure_changes_at ? c_.events.changed_gain : 1.0);
  }

  // The body at clip time t (nullopt: never visible, or the motion has ended).
  std::optional<BodyPose> BodyAt(double t) const {
    if (c_.events.body_never_visible) return std::nullopt;
    const double tm = std::max(0.0, t - c_.release_time);
    if (tm > motion_.end_time()) return std::nullopt;
    const MotionSample s = motion_.At(tm);
    return BodyPose{s.x, s.z, s.angle};
  }

  // Raw pixel box of the body with what it changes near itself: its mirror image in a wooden
  // table, its reflections in the rods (a margin of half its radius), its soft shadow on the
  // rods. Empty when off the frame.
  cv::Rect BodyBox(const BodyPose& p, int pose_index) const {
    std::vector<Vector3d> points;
    const double zt = c_.apparatus.table_z;
    for (int k = 0; k < 8; ++k) {
      const Vector3d q = Corner(p, k);
      points.push_back(q);
      if (c_.look.table == TableCover::kWood) points.emplace_back(q.x(), q.y(), 2 * zt - q.z());
    }
    AddRodShadowPoints(p, &points);
    const Vector3d centre = poses_[pose_index].rotation * Vector3d(p.x, 0, p.z) + poses_[pose_index].translation;
    return PixelBox(points, pose_index, 0.5 * a_ * c_.camera.camera.fx / centre.z() + 4);
  }

  // Raw pixel box of the body's soft shadow on the table (from every corner of the soft box).
  cv::Rect ShadowBox(const BodyPose& p, int pose_index) const {
    std::vector<Vector3d> points;
    AddShadowPoints(p, c_.apparatus.table_z, &points);
    return PixelBox(points, pose_index, 4);
  }

  // Raw pixel of the centre of the body's shadow on the table (from the soft box's centre).
  Vector2d ShadowCentre(const BodyPose& p, int pose_index) const {
    const Vector3d lamp = FootageSoftBox(c_.apparatus).centre, q(p.x, 0, p.z);
    const double s = (lamp.z() - c_.apparatus.table_z) / (lamp.z() - q.z());
    return ProjectOrOutside(c_.camera.camera, poses_[pose_index], {lamp + s * (q - lamp)}, lens_.max_ray_radius())[0];
  }

  Vector3d Corner(const BodyPose& p, int k) const {
    return Vector3d(p.x + (k & 1 ? a_ : -a_), k & 2 ? b_ : -b_, p.z + (k & 4 ? a_ : -a_));
  }

  // Points of the rods that the body shades from part of the soft box (a conservative penumbra):
  // along each rod's axis (2 mm steps within 0.4 m of the body), those from which the body's
  // bounding sphere (grown by the rod's radius) hides some of the soft box. Seen from a rod point
  // q the sphere is a cone of half angle α about q → centre; it meets the lamp's plane in an
  // ellipse about the point Lc where q → centre does, inside the circle of radius
  // |Lc − q|·tan α / cos(θ + α) (θ the cone axis' angle from the vertical); the point is kept when
  // that circle meets the square. Sampling a few points of the soft box instead misses the far
  // penumbra, where the sphere hides a spot smaller than their spacing.
  void AddRodShadowPoints(const BodyPose& p, std::vector<Vector3d>* points) const {
    const SoftBox light = FootageSoftBox(c_.apparatus);
    const Vector3d centre(p.x, 0, p.z);
    const double reach = std::max(a_, b_) + occluders_[0].r;
    for (int rod = 0; rod < 2; ++rod) {
      const Cylinder& c = occluders_[rod];
      for (double t = 0; t <= c.length; t += 0.002) {
        const Vector3d q = c.p0 + t * c.e;
        if (std::abs(q.x() - p.x) > 0.4) continue;
        const Vector3d v = centre - q;
        const double distance = v.norm();
        if (distance <= reach) {
          points->push_back(q);
          continue;
        }
        if (v.z() <= 0 || light.centre.z() <= q.z()) continue;  // the body is not towards the lamp
        const double alpha = std::asin(reach / distance), theta = std::acos(v.z() / distance);
        if (theta + alpha >= 0.5 * M_PI) {
          points->push_back(q);  // the cone reaches the horizon: keep the point
          continue;
        }
        const Vector3d lc = q + v * ((light.centre.z() - q.z()) / v.z());
        const double radius = (lc - q).norm() * std::tan(alpha) / std::cos(theta + alpha);
        const double dx = std::max(std::abs(lc.x() - light.centre.x()) - light.half_size, 0.0);
        const double dy = std::max(std::abs(lc.y() - light.centre.y()) - light.half_size, 0.0);
        if (std::hypot(dx, dy) <= radius) points->push_back(q);
      }
    }
  }

  // The body's bounding box projected from each corner of the soft box onto the plane z.
  void AddShadowPoints(const BodyPose& p, double z, std::vector<Vector3d>* points) const {
    const SoftBox light = FootageSoftBox(c_.apparatus);
    for (int k = 0; k < 8; ++k) {
      const Vector3d q = Corner(p, k);
      if (q.z() <= z) continue;
      for (int l = 0; l < 4; ++l) {
        const Vector3d lamp = light.centre + Vector3d(l & 1 ? light.half_size : -light.half_size,
                                                      l & 2 ? light.half_size : -light.half_size, 0);
        const double s = (lamp.z() - z) / (lamp.z() - q.z());
        points->push_back(lamp + s * (q - lamp));
      }
    }
  }

  cv::Rect PixelBox(const std::vector<Vector3d>& points, int pose_index, double margin) const {
    if (points.empty()) return {};
    const std::vector<Vector2d> pixels =
        ProjectOrOutside(c_.camera.camera, poses_[pose_index], points, lens_.max_ray_radius());
    double u0 = kInf, v0 = kInf, u1 = -kInf, v1 = -kInf;
    for (const Vector2d& q : pixels) {
      u0 = std::min(u0, q.x()), u1 = std::max(u1, q.x()), v0 = std::min(v0, q.y()), v1 = std::max(v1, q.y());
    }
    const cv::Rect box(static_cast<int>(std::floor(u0 - margin)), static_cast<int>(std::floor(v0 - margin)),
                       static_cast<int>(std::ceil(u1 - u0 + 2 * margin)) + 1,
                       static_cast<int>(std::ceil(v1 - v0 + 2 * margin)) + 1);
    return box & cv::Rect(0, 0, c_.camera.camera.width, c_.camera.camera.height);
  }

  Vector2d Project(const BodyPose& p, int pose_index) const {
    return ProjectApparatusPoint(c_.camera.camera, poses_[pose_index], Vector3d(p.x, 0, p.z));
  }

  // Fraction of the body's silhouette inside the frame and not hidden by the apparatus.
  double Visibility(const BodyPose& p, int pose_index) const {
    const CameraPose& pose = poses_[pose_index];
    const Vector3d eye = CameraCentre(pose), centre(p.x, 0, p.z);
    double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
    for (int k = 0; k < 8; ++k) {
      const Vector3d q = pose.rotation * (centre + Vector3d(k & 1 ? a_ : -a_, k & 2 ? b_ : -b_, k & 4 ? a_ : -a_)) +
                         pose.translation;
      x0 = std::min(x0, q.x() / q.z()), x1 = std::max(x1, q.x() / q.z());
      y0 = std::min(y0, q.y() / q.z()), y1 = std::max(y1, q.y() / q.z());
    }
    constexpr int n = 32;
    std::vector<Vector3d> hits;
    std::vector<bool> hidden;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vector3d ray_cam(x0 + (i + 0.5) / n * (x1 - x0), y0 + (j + 0.5) / n * (y1 - y0), 1);
        const Vector3d d = (pose.rotation.transpose() * ray_cam).normalized();
        const double t = RayBody(eye, d, centre, a_, b_);
        if (!std::isfinite(t)) continue;
        bool h = false;
        for (const Cylinder& cyl : occluders_) h = h || RayCylinder(eye, d, cyl.p0, cyl.e, cyl.r, cyl.length) < t;
        hits.push_back(eye + t * d);
        hidden.push_back(h);
      }
    if (hits.empty()) return 0;
    const std::vector<Vector2d> pixels = ProjectOrOutside(c_.camera.camera, pose, hits, lens_.max_ray_radius());
    int visible = 0;
    const double w = c_.camera.camera.width, h = c_.camera.camera.height;
    for (size_t k = 0; k < hits.size(); ++k) {
      const Vector2d& q = pixels[k];
      visible += !hidden[k] && q.x() >= -0.5 && q.y() >= -0.5 && q.x() <= w - 0.5 && q.y() <= h - 0.5;
    }
    return static_cast<double>(visible) / hits.size();
  }

  // The static scene (no body) as a raw linear picture, for each camera pose.
  void RenderStatic() {
    std::vector<PovrayJob> jobs = StaticJobs();
    RunJobs(jobs, poses_.size() == 1 ? 2 : 1);
    for (PovrayJob& job : jobs) static_raw_.push_back(lens_.ToRaw(job.pictures[0]));
  }

  struct PovrayJob {
    PovrayShot shot;
    std::vector<cv::Mat> pictures;
  };

  // The whole pinhole picture without the body, for each camera pose.
  std::vector<PovrayJob> StaticJobs() const {
    std::vector<PovrayJob> jobs;
    for (size_t k = 0; k < poses_.size(); ++k) {
      PovrayJob job;
      job.shot.camera = {lens_.pinhole(), poses_[k]};
      job.shot.crop = cv::Rect(0, 0, lens_.pinhole().width, lens_.pinhole().height);
      job.shot.bodies = {std::nullopt};
      jobs.push_back(job);
    }
    return jobs;
  }

  // A part of the picture that the moving body changes, rendered at its own sub-frame times:
  // sub-frame k covers [i0 + k·dt, i0 + (k + 1)·dt] and renders the pinhole window around its own
  // raw box (a long blur would otherwise render the whole smear K times); the windows share one
  // size, so that one POV-Ray run renders several.
  struct Region {
    double i0 = 0, dt = 0;
    std::vector<std::optional<BodyPose>> bodies;  // per sub-frame
    std::vector<cv::Rect> boxes, windows;         // per sub-frame: its raw box, its pinhole window
    cv::Rect box;                                 // all sub-frames' boxes: the pixels composited
    std::vector<cv::Mat> raw;                     // per sub-frame: its raw box, once rendered
  };

  // What frame f needs: its truth, and the regions the body changes. Usually one region (the body
  // with its shadow). A body high above the table casts its soft shadow far from itself: then
  // the shadow on the table is a region of its own, sampled in time by its own, slower measure
  // (a penumbra of p px moving by p/6 px between sub-frames changes the picture as little as a
  // sharp edge moving by max_step_px), while the body's region keeps the body's fine steps.
  struct FramePlan {
    int frame = 0, pose_index = 0;
    double exposure = 0;
    ClipTruth truth;
    std::vector<Region> regions;  // disjoint boxes; empty: the static scene only
  };

  FramePlan Plan(int f) const {
    FramePlan plan;
    plan.frame = f;
    plan.pose_index = PoseIndex(f);
    plan.exposure = Exposure(f);
    const int pi = plan.pose_index, H = timing_.height;
    const double E = plan.exposure, ro = timing_.readout;
    ClipTruth& truth = plan.truth;
    // Truth at the time of the centre's row (fixed point; contracts, see the header).
    truth.frame = f;
    truth.t = timing_.FrameTime(f);
    for (int it = 0; it < 60 && ro > 0; ++it) {
      const std::optional<BodyPose> b = BodyAt(truth.t);
      if (!b) break;
      const double next = timing_.FrameTime(f) + std::clamp(Project(*b, pi).y(), 0.0, H - 1.0) * ro / H;
      const bool done = std::abs(next - truth.t) < 1e-12;
      truth.t = next;
      if (done) break;
    }
    // The body over the exposure of every row (a superset), then of the rows it touches.
    const double t_first = timing_.FrameTime(f) - E / 2, t_last = timing_.RowTime(f, H - 1) + E / 2;
    cv::Rect box0;
    bool ends = false;
    for (int k = 0; k <= 16; ++k) {
      const std::optional<BodyPose> b = BodyAt(t_first + (t_last - t_first) * k / 16);
      if (b) box0 |= BodyBox(*b, pi) | ShadowBox(*b, pi);
      else ends = true;
    }
    const std::optional<BodyPose> at_truth = BodyAt(truth.t);
    truth.present = at_truth.has_value() && !ends;
    if (truth.present) {
      truth.x = at_truth->x, truth.z = at_truth->z;
      const Vector2d uv = Project(*at_truth, pi);
      truth.u = uv.x(), truth.v = uv.y();
      truth.visibility = Visibility(*at_truth, pi);
    }
    // A body whose motion ends during the exposure is not drawn (see the header).
    if (ends || box0.empty()) return plan;
    const double i0 = timing_.RowTime(f, box0.y) - E / 2;
    const double i1 = timing_.RowTime(f, box0.y + box0.height - 1) + E / 2;
    // Speeds in px/s: of the fastest point of the body (of its pattern, if painted), and of its
    // shadow's centre; the shadow's penumbra in px.
    double speed = 0, shadow_speed = 0, penumbra = kInf;
    constexpr int n = 16;
    for (int k = 0; k < n; ++k) {
      const double ta = i0 + (i1 - i0) * k / n, tb = i0 + (i1 - i0) * (k + 1) / n;
      const BodyPose a = *BodyAt(ta), b = *BodyAt(tb);
      const Vector3d cc = poses_[pi].rotation * Vector3d(b.x, 0, b.z) + poses_[pi].translation;
      const double px_per_m = c_.camera.camera.fx / cc.z();
      const double spin = c_.look.band_half_width > 0 ? a_ * px_per_m * std::abs(b.angle - a.angle) : 0;
      speed = std::max(speed, ((Project(b, pi) - Project(a, pi)).norm() + spin) / (tb - ta));
      shadow_speed = std::max(shadow_speed, (ShadowCentre(b, pi) - ShadowCentre(a, pi)).norm() / (tb - ta));
      const SoftBox light = FootageSoftBox(c_.apparatus);
      const double height = b.z - c_.apparatus.table_z;
      penumbra = std::min(penumbra, 2 * light.half_size * height / (light.centre.z() - b.z) * px_per_m);
    }
    auto subframes = [&](double px_per_s, double step_px) {
      return std::clamp(static_cast<int>(std::ceil((i1 - i0) * px_per_s / step_px)), 1, c_.max_subframes);
    };
    const int K = subframes(speed, c_.max_step_px);
    Region body = MakeRegion(i0, i1, K, pi, /*body=*/true, /*shadow=*/false);
    const int K_shadow = subframes(shadow_speed, c_.max_step_px * std::max(1.0, penumbra / 6));
    Region shadow = MakeRegion(i0, i1, K_shadow, pi, /*body=*/false, /*shadow=*/true);
    const cv::Rect grown(body.box.x - 2, body.box.y - 2, body.box.width + 4, body.box.height + 4);
    if (!(grown & shadow.box).empty()) {
      // Overlapping: one region with both, at the body's steps.
      body = MakeRegion(i0, i1, K, pi, /*body=*/true, /*shadow=*/true);
      if (!body.box.empty()) plan.regions.push_back(std::move(body));
      return plan;
    }
    if (!body.box.empty()) plan.regions.push_back(std::move(body));
    if (!shadow.box.empty()) plan.regions.push_back(std::move(shadow));
    return plan;
  }

  // K sub-frames over [i0, i1] with the windows of the body (and its nearby shadow and
  // reflections) and/or of its shadow on the table.
  Region MakeRegion(double i0, double i1, int K, int pi, bool body, bool shadow) const {
    Region region;
    region.i0 = i0;
    region.dt = (i1 - i0) / K;
    cv::Size size;
    for (int k = 0; k < K; ++k) {
      region.bodies.push_back(BodyAt(i0 + (k + 0.5) * region.dt));
      cv::Rect box;
      if (body) box |= BodyBox(*region.bodies.back(), pi);
      if (shadow) box |= ShadowBox(*region.bodies.back(), pi);
      region.boxes.push_back(box);
      region.box |= box;
      if (!box.empty()) {
        region.windows.push_back(lens_.PinholeWindow(box));
        size.width = std::max(size.width, region.windows.back().width);
        size.height = std::max(size.height, region.windows.back().height);
      } else {
        region.windows.emplace_back();
      }
    }
    const cv::Rect pinhole(0, 0, lens_.pinhole().width, lens_.pinhole().height);
    for (cv::Rect& w : region.windows) {
      // Grown to the common size about its own corner, moved back inside the picture.
      w = cv::Rect(std::clamp(w.x, 0, pinhole.width - size.width), std::clamp(w.y, 0, pinhole.height - size.height),
                   size.width, size.height);
    }
    return region;
  }

  // Renders the sub-frames of the plans, several POV-Ray processes at once (POV-Ray 3.7 idles
  // ~0.2 s per picture in its own polling loops, so one process at a time leaves the CPU idle).
  // A region of one sub-frame with the same pose and window as one already rendered (a body at
  // rest) is reused.
  void Render(std::vector<FramePlan>& plans) {
    Batch batch = Jobs(plans);
    std::vector<PovrayJob>& jobs = batch.jobs;
    const std::vector<Part>& parts = batch.parts;
    RunJobs(jobs, 1);
    for (size_t j = 0; j < jobs.size(); ++j) {
      Region& region = *parts[j].region;
      for (size_t k = 0; k < jobs[j].pictures.size(); ++k) {
        const size_t i = parts[j].first + k;
        if (!region.boxes[i].empty())
          region.raw[i] = lens_.ToRaw(jobs[j].pictures[k], region.windows[i], region.boxes[i]);
      }
      if (region.bodies.size() == 1) {
        if (rest_.size() > 16) rest_.clear();
        rest_[RestKey(region, parts[j].pose_index)] = region.raw[0];
      }
    }
    for (auto& [region, job] : batch.copies) region->raw[0] = parts[job].region->raw[0];
  }

  struct Part {
    Region* region;
    int pose_index;
    size_t first;  // its first sub-frame
  };
  struct Batch {
    std::vector<PovrayJob> jobs;
    std::vector<Part> parts;                         // per job: the sub-frames it renders
    std::vector<std::pair<Region*, size_t>> copies;  // regions that take a job's picture
  };

  // The POV-Ray jobs of the plans' sub-frames, `subframes` counted; a resting region rendered
  // before (rest_) takes its picture now, one rendered in this batch becomes a copy.
  Batch Jobs(std::vector<FramePlan>& plans) {
    Batch batch;
    std::vector<PovrayJob>& jobs = batch.jobs;
    std::vector<Part>& parts = batch.parts;
    std::map<std::string, size_t> pending;  // rest key -> its job in this batch
    for (FramePlan& plan : plans)
      for (Region& region : plan.regions) {
        const size_t K = region.bodies.size();
        region.raw.assign(K, cv::Mat());
        subframes += static_cast<int>(K);
        if (K == 1) {
          const std::string key = RestKey(region, plan.pose_index);
          if (const auto it = rest_.find(key); it != rest_.end()) {
            region.raw[0] = it->second;
            continue;
          }
          if (const auto it = pending.find(key); it != pending.end()) {
            batch.copies.emplace_back(&region, it->second);
            continue;
          }
          pending[key] = jobs.size();
        }
        // Chunks of ≤ 6 sub-frames: one process per chunk, so that a region's sub-frames spread
        // over the workers.
        const size_t chunks = (K + 5) / 6, per = (K + chunks - 1) / chunks;
        for (size_t first = 0; first < K; first += per) {
          PovrayJob job;
          const size_t last = std::min(K, first + per);
          job.shot.camera = {lens_.pinhole(), poses_[plan.pose_index]};
          job.shot.crop = region.windows[first];
          job.shot.bodies.assign(region.bodies.begin() + first, region.bodies.begin() + last);
          for (size_t k = first; k < last; ++k) job.shot.crop_offsets.push_back(region.windows[k].tl());
          jobs.push_back(job);
          parts.push_back({&region, plan.pose_index, first});
        }
      }
    return batch;
  }

  // The linear raw frame of a rendered plan (before vignetting, gain and noise): each row the
  // static scene times the light's mean over its window; each region's box Σ_k w_k·picture_k.
  cv::Mat Compose(const FramePlan& plan) const {
    const int H = timing_.height, f = plan.frame;
    const double E = plan.exposure;
    auto window = [&](int r) {
      const double t = timing_.RowTime(f, r);
      return std::pair<double, double>(t - E / 2, t + E / 2);
    };
    cv::Mat frame = static_raw_[plan.pose_index].clone();
    double gain0 = 0;
    for (int r = 0; r < H; ++r) {
      if (r == 0 || timing_.readout > 0) {
        const auto [a, b] = window(r);
        gain0 = c_.light.Integral(a, b) / E;
      }
      frame.row(r) *= gain0;
    }
    for (const Region& region : plan.regions) {
      const cv::Mat still = static_raw_[plan.pose_index](region.box);
      cv::Mat acc = cv::Mat::zeros(region.box.size(), CV_32FC3), picture;
      for (size_t k = 0; k < region.bodies.size(); ++k) {
        // Sub-frame k over the region's box: the static scene, its own box pasted in.
        still.copyTo(picture);
        if (!region.boxes[k].empty()) region.raw[k].copyTo(picture(region.boxes[k] - region.box.tl()));
        for (int r = 0; r < region.box.height; ++r) {
          const auto [wa, wb] = window(region.box.y + r);
          const double a = std::max(wa, region.i0 + k * region.dt), b = std::min(wb, region.i0 + (k + 1) * region.dt);
          if (b <= a) continue;
          cv::scaleAdd(picture.row(r), c_.light.Integral(a, b) / E, acc.row(r), acc.row(r));
        }
      }
      acc.copyTo(frame(region.box));
    }
    return frame;
  }

  // What POV-Ray would be asked for (its scene text and picture size) and whether the picture
  // cache holds it already.
  PovrayWork Work(const PovrayJob& job) const {
    PovrayWork w;
    w.subframes = static_cast<int>(job.shot.bodies.size());
    w.pixels = static_cast<double>(job.shot.crop.area()) * w.subframes;
    PovrayOptions options = c_.povray;
    options.picture_cache = pictures_.empty() ? std::string() : pictures_.string();
    w.cached = PovrayPicturesCached(Text(job), job.shot.crop.size(), w.subframes, options);
    return w;
  }

  // The chessboard views (camera frame as the scene's frame), rendered in parallel.
  std::vector<cv::Mat> RenderBoards(const std::vector<BoardInView>& boards) {
    std::vector<PovrayJob> jobs;
    for (const BoardInView& board : boards) {
      PovrayJob job;
      job.shot.camera = {lens_.pinhole(), CameraPose{}};
      job.shot.crop = cv::Rect(0, 0, lens_.pinhole().width, lens_.pinhole().height);
      job.shot.bodies = {std::nullopt};
      job.shot.board = board;
      jobs.push_back(job);
    }
    RunJobs(jobs, 1);
    std::vector<cv::Mat> out;
    for (PovrayJob& job : jobs) out.push_back(lens_.ToRaw(job.pictures[0]));
    return out;
  }

  const cv::Mat& vignetting() const { return vignetting_; }
  int povray_runs = 0, povray_cached = 0, subframes = 0;
  double povray_cpu = 0;

 private:
  std::string Text(const PovrayJob& job) const {
    return job.shot.board ? PovrayBoardSceneText(job.shot) : PovraySceneText(c_.scene, c_.apparatus, c_.look, job.shot);
  }

  // Runs the jobs on up to povray_processes POV-Ray processes at once (`threads` each, at most
  // povray.threads).
  void RunJobs(std::vector<PovrayJob>& jobs, int threads) {
    const size_t most_workers = static_cast<size_t>(std::max(1, c_.povray_processes));
    threads = std::clamp(threads, 1, std::max(1, c_.povray.threads));
    std::atomic<size_t> next{0};
    std::mutex mutex;
    std::exception_ptr failure;
    auto worker = [&](int id) {
      const std::string dir = (work_ / ("povray-" + std::to_string(id))).string();
      for (size_t j = next++; j < jobs.size(); j = next++) {
        try {
          PovrayJob& job = jobs[j];
          const std::string text = Text(job);
          PovrayOptions options = c_.povray;
          options.threads = threads;
          options.picture_cache = pictures_.empty() ? std::string() : pictures_.string();
          PovrayRun run = RunPovray(text, job.shot.crop.size(), static_cast<int>(job.shot.bodies.size()), dir, options);
          job.pictures = std::move(run.pictures);
          std::lock_guard<std::mutex> lock(mutex);
          (run.cached ? povray_cached : povray_runs) += 1;
          povray_cpu += run.cpu_seconds;
        } catch (...) {
          std::lock_guard<std::mutex> lock(mutex);
          if (!failure) failure = std::current_exception();
          next = jobs.size();
        }
      }
    };
    const int workers = static_cast<int>(std::min(most_workers, jobs.size()));
    std::vector<std::thread> threads_;
    for (int w = 1; w < workers; ++w) threads_.emplace_back(worker, w);
    worker(0);
    for (std::thread& t : threads_) t.join();
    if (failure) std::rethrow_exception(failure);
  }

  std::string RestKey(const Region& region, int pose_index) const {
    const BodyPose& b = *region.bodies[0];
    const cv::Rect &w = region.windows[0], &x = region.box;
    char text[200];
    std::snprintf(text, sizeof text, "%d %d %d %d %d %d %d %d %d %.17g %.17g %.17g", pose_index, w.x, w.y, w.width,
                  w.height, x.x, x.y, x.width, x.height, b.x, b.z, b.angle);
    return text;
  }

  const FootageCondition& c_;
  fs::path work_, pictures_;
  LensRemap lens_;
  Motion motion_;
  ShutterTiming timing_;
  cv::Mat vignetting_;
  std::vector<Cylinder> occluders_;
  std::vector<CameraPose> poses_;
  std::vector<cv::Mat> static_raw_;
  double a_ = 0, b_ = 0;
  std::map<std::string, cv::Mat> rest_;
};

void Validate(const FootageCondition& c) {
  ValidateIntrinsics(c.camera.camera, "camera");
  if (c.frames < 1) throw InputError("frames", "must be >= 1");
  if (!(c.shutter.fps > 0 && std::isfinite(c.shutter.fps))) throw InputError("fps", "must be > 0");
  if (!(c.shutter.exposure > 0 && c.shutter.exposure <= 1 / c.shutter.fps * (1 + 1e-12)))
    throw InputError("exposure", "must be in (0, 1/fps] (a shutter angle of at most 360 degrees)");
  if (!(c.shutter.readout >= 0 && c.shutter.readout <= 1 / c.shutter.fps))
    throw InputError("readout", "must be in [0, 1/fps]");
  if (c.events.exposure_changes_at >= 0 &&
      !(c.events.changed_exposure > 0 && c.events.changed_exposure <= 1 / c.shutter.fps * (1 + 1e-12)))
    throw InputError("changed exposure", "must be in (0, 1/fps]");
  if (!(c.max_step_px > 0)) throw InputError("max_step_px", "must be > 0");
  if (!(c.gain > 0) || !(c.sensor.full_well > 0) || !(c.sensor.read_noise >= 0))
    throw InputError("sensor", "gain and full well must be > 0, read noise >= 0");
  if (c.boards < 0) throw InputError("boards", "must be >= 0");
}

std::string FileName(const char* pattern, int k) {
  char name[64];
  std::snprintf(name, sizeof name, pattern, k);
  return name;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error(path.string() + ": cannot encode PNG");
  WriteFileAtomically(path.string(), std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

double ProcessCpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Renders the chessboard views of the condition's camera into `folder` (shared by all clips of
// that camera and sensor), unless they are there.
std::vector<std::string> EnsureBoards(const FootageCondition& c, const fs::path& root, FootageRenderer& renderer,
                                      const FootageProgress& progress) {
  const fs::path folder = root / ("boards-" + internal::ContentKey(DescribeBoards(c).dump()));
  std::vector<std::string> paths;
  for (int k = 0; k < c.boards; ++k) paths.push_back((folder / FileName("board_%02d.png", k)).string());
  if (fs::exists(folder / "complete")) return paths;
  fs::create_directories(folder);
  const std::vector<CameraPose> poses = RandomBoardPoses(c.camera.camera, c.board_target, c.boards, 7);
  std::vector<BoardInView> boards;
  for (const CameraPose& pose : poses) boards.push_back({c.board_target, pose, 1.0});
  if (progress.report) progress.report("chessboard views", 0, c.boards);
  const std::vector<cv::Mat> pictures = renderer.RenderBoards(boards);
  for (int k = 0; k < c.boards; ++k) {
    std::vector<cv::Mat> channels(3);
    cv::split(pictures[k], channels);
    for (cv::Mat& ch : channels) ch = ch.mul(renderer.vignetting(), c.gain);
    cv::Mat lit;
    cv::merge(channels, lit);
    WritePng(paths[k], c.sensor.ToFrame8(lit, 1000000 + k));
  }
  WriteFileAtomically((folder / "complete").string(), DescribeBoards(c).dump(2) + "\n");
  return paths;
}

}  // namespace

ordered_json DescribeFootage(const FootageCondition& c) {
  const Body& body = c.scene.body();
  ordered_json j;
  j["generator"] = kGeneratorDigest;
  j["name"] = c.name;
  j["body"] = {{"kind", body.kind == BodyKind::kSphere ? "sphere" : "spheroid"},
               {"across_m", body.across},
               {"along_m", body.along}};
  j["rails"] = {{"tan_theta", c.scene.rails().tan_theta},
                {"tan_half_alpha", c.scene.rails().tan_half_alpha},
                {"rod_radius_m", c.scene.rod_radius()}};
  const FootageApparatus& a = c.apparatus;
  j["apparatus"] = {{"crossbar_x_m", a.crossbar_x}, {"crossbar_radius_m", a.crossbar_radius},
                    {"post_radius_m", a.post_radius}, {"rail_overhang_m", a.rail_overhang},
                    {"table_z_m", a.table_z},        {"wall_y_m", a.wall_y},
                    {"marks_m", a.marks}};
  j["look"] = {{"table", c.look.table == TableCover::kWood ? "wood" : "cloth"},
               {"body_rgb", {c.look.body_rgb.x(), c.look.body_rgb.y(), c.look.body_rgb.z()}},
               {"band_rgb", {c.look.band_rgb.x(), c.look.band_rgb.y(), c.look.band_rgb.z()}},
               {"band_half_width_m", c.look.band_half_width},
               {"light", c.look.light}};
  j["camera"] = DescribeCamera(c.camera.camera);
  j["pose"] = DescribePose(c.camera.pose);
  j["motion"] = {{"x0_m", c.x0}, {"release_time_s", c.release_time}};
  j["frames"] = c.frames;
  j["shutter"] = {{"fps", c.shutter.fps}, {"exposure_s", c.shutter.exposure}, {"readout_s", c.shutter.readout},
                  {"t0_s", c.shutter.t0}};
  j["light"] = {{"flicker_depth", c.light.flicker_depth}, {"flicker_hz", c.light.flicker_hz},
                {"flicker_phase", c.light.flicker_phase}, {"drift_depth", c.light.drift_depth},
                {"drift_period_s", c.light.drift_period}, {"drift_phase", c.light.drift_phase}};
  j["sensor"] = DescribeSensor(c.sensor, c.gain, c.vignetting);
  j["codec"] = CodecName(c.codec);
  j["bit_rate"] = c.bit_rate;
  j["max_step_px"] = c.max_step_px;
  j["max_subframes"] = c.max_subframes;
  j["events"] = {{"body_never_visible", c.events.body_never_visible},
                 {"camera_moves_at", c.events.camera_moves_at},
                 {"moved_pose", DescribePose(c.events.moved_pose)},
                 {"exposure_changes_at", c.events.exposure_changes_at},
                 {"changed_exposure_s", c.events.changed_exposure},
                 {"changed_gain", c.events.changed_gain}};
  j["boards"] = DescribeBoards(c);
  return j;
}

std::string FootageKey(const FootageCondition& c) { return internal::ContentKey(DescribeFootage(c).dump()); }

std::string FootageCacheRoot() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  fs::path base;
  if (xdg && *xdg) base = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home) base = fs::path(home) / ".cache";
  else base = fs::temp_directory_path();
  return (base / "uphill" / "clips").string();
}

std::vector<ApparatusPoint> FootageApparatusPoints(const FootageCondition& c) {
  return VisibleApparatusPoints(c.camera.camera, c.camera.pose,
                                ApparatusCalibrationPoints(c.scene.rails(), c.apparatus.crossbar_x, c.apparatus.table_z,
                                                           c.apparatus.marks));
}

FootageWork PlanFootage(const FootageCondition& condition, const std::string& cache_root) {
  Validate(condition);
  const fs::path root = fs::absolute(cache_root);
  FootageWork work;
  work.clip_cached = fs::exists(root / FootageKey(condition) / "condition.json");
  work.boards_cached =
      condition.boards == 0 ||
      fs::exists(root / ("boards-" + internal::ContentKey(DescribeBoards(condition).dump())) / "complete");
  FootageRenderer renderer(condition, fs::path(), root / "pictures");
  for (const auto& job : renderer.StaticJobs()) {
    const PovrayWork w = renderer.Work(job);
    work.static_pictures += 1;
    work.static_to_render += !w.cached;
    work.static_pixels_to_render += w.cached ? 0 : w.pixels;
  }
  // All frames in one batch, so that a resting body's picture is shared as RenderFootage shares it.
  std::vector<FootageRenderer::FramePlan> plans;
  for (int f = 0; f < condition.frames; ++f) plans.push_back(renderer.Plan(f));
  auto batch = renderer.Jobs(plans);
  std::map<const void*, int> frame_of;  // region -> index of its frame
  for (size_t i = 0; i < plans.size(); ++i) {
    work.frames.push_back({plans[i].frame});
    for (const auto& region : plans[i].regions) frame_of[&region] = static_cast<int>(i);
  }
  for (size_t j = 0; j < batch.jobs.size(); ++j) {
    const PovrayWork w = renderer.Work(batch.jobs[j]);
    FootageFrameWork& frame = work.frames[frame_of.at(batch.parts[j].region)];
    frame.subframes += w.subframes;
    work.subframes += w.subframes;
    if (w.cached) continue;
    frame.subframes_to_render += w.subframes;
    frame.pixels_to_render += w.pixels;
    work.runs_to_render += 1;
    work.subframes_to_render += w.subframes;
    work.pixels_to_render += w.pixels;
  }
  return work;
}

FootageFiles RenderFootage(const FootageCondition& condition, const std::string& cache_root, bool fresh,
                           const FootageProgress& progress) {
  Validate(condition);
  const fs::path root = fs::absolute(cache_root);
  const fs::path folder = root / FootageKey(condition);
  const std::string ext = condition.codec == VideoCodec::kFfv1 ? ".mkv" : ".mp4";
  FootageFiles files;
  files.folder = folder.string();
  files.video = (folder / ("clip" + ext)).string();
  files.truth_csv = (folder / "truth.csv").string();
  files.points_csv = (folder / "points.csv").string();
  files.first_frame = (folder / "frame0.png").string();
  files.camera_truth = (folder / "camera_truth.json").string();
  files.scene_truth = (folder / "scene_truth.json").string();
  const fs::path boards_marker = root / ("boards-" + internal::ContentKey(DescribeBoards(condition).dump())) / "complete";
  if (!fresh && fs::exists(folder / "condition.json") && (condition.boards == 0 || fs::exists(boards_marker))) {
    const nlohmann::json saved = ReadJsonFile((folder / "condition.json").string());
    files.from_cache = true;
    files.render_wall_seconds = saved.value("render_wall_s", 0.0);
    files.render_cpu_seconds = saved.value("render_cpu_s", 0.0);
    files.povray_runs = saved.value("povray_runs", 0);
    files.subframes = saved.value("subframes", 0);
    for (int k = 0; k < condition.boards; ++k)
      files.boards.push_back((boards_marker.parent_path() / FileName("board_%02d.png", k)).string());
    return files;
  }
  const auto start = std::chrono::steady_clock::now();
  const double cpu0 = ProcessCpuSeconds();
  // Render into a private folder, then rename it into place: a folder under its key is complete.
  const fs::path partial = root / (FootageKey(condition) + ".partial-" + std::to_string(getpid()));
  fs::remove_all(partial);
  fs::create_directories(partial);
  FootageRenderer renderer(condition, partial, fresh ? fs::path() : root / "pictures");
  files.boards = EnsureBoards(condition, root, renderer, progress);
  if (progress.report) progress.report("static scene", 0, condition.frames);
  renderer.RenderStatic();
  VideoEncoderSettings enc;
  enc.codec = condition.codec;
  enc.fps = condition.shutter.fps;
  enc.bit_rate = condition.bit_rate;
  const CameraIntrinsics& k = condition.camera.camera;
  VideoEncoder encoder((partial / ("clip" + ext)).string(), cv::Size(k.width, k.height), enc);
  std::vector<ClipTruth> truth;
  // Frames in batches: their sub-frames render together (the pool stays busy), then compose.
  constexpr int kBatch = 8;
  for (int first = 0; first < condition.frames; first += kBatch) {
    if (progress.report) progress.report("frames", first, condition.frames);
    std::vector<FootageRenderer::FramePlan> plans;
    for (int f = first; f < std::min(condition.frames, first + kBatch); ++f) plans.push_back(renderer.Plan(f));
    renderer.Render(plans);
    for (const FootageRenderer::FramePlan& plan : plans) {
      cv::Mat linear = renderer.Compose(plan);
      std::vector<cv::Mat> channels(3);
      cv::split(linear, channels);
      for (cv::Mat& ch : channels) ch = ch.mul(renderer.vignetting(), renderer.Gain(plan.frame));
      cv::merge(channels, linear);
      const cv::Mat frame = condition.sensor.ToFrame8(linear, static_cast<std::uint64_t>(plan.frame));
      if (plan.frame == 0) WritePng(partial / "frame0.png", frame);
      encoder.Write(frame);
      truth.push_back(plan.truth);
    }
  }
  encoder.Finish();
  WriteClipTruthCsv((partial / "truth.csv").string(), truth);
  std::ostringstream points;
  points << "name,u,v,x_mm,y_mm,z_mm\n";
  for (const ApparatusPoint& p : FootageApparatusPoints(condition)) {
    char line[200];
    std::snprintf(line, sizeof line, "%s,%.4f,%.4f,%.4f,%.4f,%.4f\n", p.name.c_str(), p.pixel.x(), p.pixel.y(),
                  p.position.x() * 1e3, p.position.y() * 1e3, p.position.z() * 1e3);
    points << line;
  }
  WriteFileAtomically((partial / "points.csv").string(), points.str());
  CalibrationSummary summary;
  summary.method = "the true camera of the POV-Ray footage (src/vision/footage_clip.hpp)";
  summary.verdict = "exact";
  summary.reasons = {"the camera that rendered the clip: no calibration error"};
  WriteCameraFile((partial / "camera_truth.json").string(), k, summary);
  WriteSceneFile((partial / "scene_truth.json").string(), condition.camera, summary);
  for (const fs::directory_entry& e : fs::directory_iterator(partial))
    if (e.is_directory() && e.path().filename().string().rfind("povray-", 0) == 0) fs::remove_all(e.path());
  files.render_wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  files.render_cpu_seconds = ProcessCpuSeconds() - cpu0 + renderer.povray_cpu;
  files.povray_runs = renderer.povray_runs;
  files.subframes = renderer.subframes;
  ordered_json description = DescribeFootage(condition);
  description["render_wall_s"] = files.render_wall_seconds;
  description["render_cpu_s"] = files.render_cpu_seconds;
  description["povray_runs"] = files.povray_runs;
  description["subframes"] = files.subframes;
  WriteFileAtomically((partial / "condition.json").string(), description.dump(2) + "\n");
  std::error_code ec;
  fs::remove_all(folder, ec);
  fs::rename(partial, folder);
  return files;
}

std::vector<ClipTruth> ReadFootageTruth(const std::string& path) {
  const CsvTable table = ReadCsvFile(path);
  const char* names[] = {"frame", "t", "x", "z", "u", "v", "visibility"};
  int col[7];
  for (int i = 0; i < 7; ++i) {
    col[i] = table.Column(names[i]);
    if (col[i] < 0) throw InputError(path, std::string("has no column ") + names[i]);
  }
  std::vector<ClipTruth> out;
  for (const CsvRow& row : table.rows) {
    if (!row.error.empty()) throw InputError(path + ", row " + std::to_string(row.row), row.error);
    auto number = [&](int i) {
      const std::string context = CellContext(table, row.row, names[i]);
      return ParseQuantity(row.cells[col[i]], Dimension::kDimensionless, context);
    };
    ClipTruth t;
    t.frame = static_cast<int>(number(0));
    t.t = number(1);
    t.present = !row.cells[col[2]].empty();
    if (t.present) {
      t.x = number(2) * 1e-3, t.z = number(3) * 1e-3, t.u = number(4), t.v = number(5);
      t.visibility = number(6);
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace uphill
