#include "footage_renderer.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "vision/camera.hpp"

namespace uphill::internal {

namespace fs = std::filesystem;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

}  // namespace

FootageRenderer::FootageRenderer(const FootageCondition& c, const fs::path& work, const fs::path& pictures)
    : c_(c), work_(work), pictures_(pictures), lens_(c.camera.camera), motion_(c.scene, c.x0, c.motion) {
  timing_ = c.shutter;
  timing_.height = c.camera.camera.height;
  vignetting_ = lens_.Vignetting(c.vignetting);
  occluders_ = Occluders(c.scene, c.apparatus);
  poses_.push_back(c.camera.pose);
  if (c.events.camera_moves_at >= 0) poses_.push_back(c.events.moved_pose);
  a_ = c.scene.body().across;
  b_ = c.scene.body().along;
}

int FootageRenderer::PoseIndex(int frame) const {
  return c_.events.camera_moves_at >= 0 && frame >= c_.events.camera_moves_at ? 1 : 0;
}

double FootageRenderer::Exposure(int frame) const {
  return c_.events.exposure_changes_at >= 0 && frame >= c_.events.exposure_changes_at ? c_.events.changed_exposure
                                                                                       : timing_.exposure;
}

double FootageRenderer::Gain(int frame) const {
  return c_.gain *
         (c_.events.exposure_changes_at >= 0 && frame >= c_.events.exposure_changes_at ? c_.events.changed_gain : 1.0);
}

std::optional<BodyPose> FootageRenderer::BodyAt(double t) const {
  if (c_.events.body_never_visible) return std::nullopt;
  const double tm = std::max(0.0, t - c_.release_time);
  if (tm > motion_.end_time()) return std::nullopt;
  const MotionSample s = motion_.At(tm);
  return BodyPose{s.x, s.z, s.angle};
}

cv::Rect FootageRenderer::BodyBox(const BodyPose& p, int pose_index) const {
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

cv::Rect FootageRenderer::ShadowBox(const BodyPose& p, int pose_index) const {
  std::vector<Vector3d> points;
  AddShadowPoints(p, c_.apparatus.table_z, &points);
  return PixelBox(points, pose_index, 4);
}

Vector2d FootageRenderer::ShadowCentre(const BodyPose& p, int pose_index) const {
  const Vector3d lamp = FootageSoftBox(c_.apparatus).centre, q(p.x, 0, p.z);
  const double s = (lamp.z() - c_.apparatus.table_z) / (lamp.z() - q.z());
  return ProjectOrOutside(c_.camera.camera, poses_[pose_index], {lamp + s * (q - lamp)}, lens_.max_ray_radius())[0];
}

Vector3d FootageRenderer::Corner(const BodyPose& p, int k) const {
  return Vector3d(p.x + (k & 1 ? a_ : -a_), k & 2 ? b_ : -b_, p.z + (k & 4 ? a_ : -a_));
}

void FootageRenderer::AddRodShadowPoints(const BodyPose& p, std::vector<Vector3d>* points) const {
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

void FootageRenderer::AddShadowPoints(const BodyPose& p, double z, std::vector<Vector3d>* points) const {
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

cv::Rect FootageRenderer::PixelBox(const std::vector<Vector3d>& points, int pose_index, double margin) const {
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

Vector2d FootageRenderer::Project(const BodyPose& p, int pose_index) const {
  return ProjectApparatusPoint(c_.camera.camera, poses_[pose_index], Vector3d(p.x, 0, p.z));
}

double FootageRenderer::Visibility(const BodyPose& p, int pose_index) const {
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

void FootageRenderer::RenderStatic() {
  std::vector<PovrayJob> jobs = StaticJobs();
  RunJobs(jobs, poses_.size() == 1 ? 2 : 1);
  for (PovrayJob& job : jobs) static_raw_.push_back(lens_.ToRaw(job.pictures[0]));
}

std::vector<FootageRenderer::PovrayJob> FootageRenderer::StaticJobs() const {
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

FootageRenderer::FramePlan FootageRenderer::Plan(int f) const {
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
    const bool painted = c_.look.band_half_width > 0 || c_.look.pattern != BodyPattern::kPlain;
    const double spin = painted ? a_ * px_per_m * std::abs(b.angle - a.angle) : 0;
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

FootageRenderer::Region FootageRenderer::MakeRegion(double i0, double i1, int K, int pi, bool body, bool shadow) const {
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

void FootageRenderer::Render(std::vector<FramePlan>& plans) {
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

FootageRenderer::Batch FootageRenderer::Jobs(std::vector<FramePlan>& plans) {
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

cv::Mat FootageRenderer::Compose(const FramePlan& plan) const {
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

PovrayWork FootageRenderer::Work(const PovrayJob& job) const {
  PovrayWork w;
  w.subframes = static_cast<int>(job.shot.bodies.size());
  w.pixels = static_cast<double>(job.shot.crop.area()) * w.subframes;
  PovrayOptions options = c_.povray;
  options.picture_cache = pictures_.empty() ? std::string() : pictures_.string();
  w.cached = PovrayPicturesCached(Text(job), job.shot.crop.size(), w.subframes, options);
  return w;
}

std::vector<cv::Mat> FootageRenderer::RenderBoards(const std::vector<BoardInView>& boards) {
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

std::string FootageRenderer::Text(const PovrayJob& job) const {
  return job.shot.board ? PovrayBoardSceneText(job.shot) : PovraySceneText(c_.scene, c_.apparatus, c_.look, job.shot);
}

void FootageRenderer::RunJobs(std::vector<PovrayJob>& jobs, int threads) {
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

std::string FootageRenderer::RestKey(const Region& region, int pose_index) const {
  const BodyPose& b = *region.bodies[0];
  const cv::Rect &w = region.windows[0], &x = region.box;
  char text[200];
  std::snprintf(text, sizeof text, "%d %d %d %d %d %d %d %d %d %.17g %.17g %.17g", pose_index, w.x, w.y, w.width,
                w.height, x.x, x.y, x.width, x.height, b.x, b.z, b.angle);
  return text;
}

}  // namespace uphill::internal
