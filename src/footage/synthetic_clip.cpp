#include "footage/synthetic_clip.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "io/atomic_file.hpp"
#include "model/input_error.hpp"
#include "footage/sensor_model.hpp"

namespace uphill {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::Vector3f;

constexpr double kInf = std::numeric_limits<double>::infinity();

enum ObjectId : std::uint8_t { kWall, kTable, kRuler, kRodMinus, kRodPlus, kTape, kCrossbar, kFoot, kBody, kNone };

// The ruler on the table (ClipApparatus::ruler): 30 mm wide, its near edge at y = kRulerNearY, from
// x = -20 mm to 1020 mm, with a tick every 10 mm from its far edge (5 mm long, 10 mm every 50 mm,
// 15 mm every 100 mm), 1 mm wide; x = 0 at O.
constexpr double kRulerNearY = -0.16, kRulerWidth = 0.03, kTickHalfWidth = 0.0005;
bool OnRuler(double x, double y) {
  return y >= kRulerNearY && y <= kRulerNearY + kRulerWidth && x >= -0.02 && x <= 1.02;
}
bool OnTick(double x, double y) {
  const long cm = std::lround(x / 0.01);
  if (std::abs(x - 0.01 * cm) > kTickHalfWidth) return false;
  const double length = cm % 10 == 0 ? 0.015 : cm % 5 == 0 ? 0.010 : 0.005;
  return y >= kRulerNearY + kRulerWidth - length;
}


// Band-limited value noise in [0, 1]: hashed lattice values, quintic interpolation.
double LatticeValue(long i, long j) {
  std::uint32_t h = static_cast<std::uint32_t>(i) * 374761393u + static_cast<std::uint32_t>(j) * 668265263u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return static_cast<double>(h ^ (h >> 16)) / 4294967295.0;
}
double ValueNoise(double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const long i = static_cast<long>(fx), j = static_cast<long>(fy);
  auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
  const double sx = fade(x - fx), sy = fade(y - fy);
  const double a = LatticeValue(i, j) + sx * (LatticeValue(i + 1, j) - LatticeValue(i, j));
  const double b = LatticeValue(i, j + 1) + sx * (LatticeValue(i + 1, j + 1) - LatticeValue(i, j + 1));
  return a + sy * (b - a);
}

// A light wood grain: features of 5 mm and more (about 5 px in the default view), grain lines
// along y so that the grazing view of the far table does not alias.
double TableTexture(double x, double y) {
  const double grain = std::sin(2 * M_PI * (x / 0.009 + 0.8 * ValueNoise(x / 0.05, y / 0.08)));
  return 0.86 + 0.09 * (ValueNoise(x / 0.03, y / 0.03) - 0.5) + 0.06 * (ValueNoise(x / 0.011, y / 0.011) - 0.5) +
         0.035 * grain;
}

// Smallest t > 0 where |w⊥ + t·d⊥| = r about the axis e through p0 with axial coordinate in [s0, s1].
double HitCylinder(const Vector3d& o, const Vector3d& d, const Vector3d& p0, const Vector3d& e, double r, double s0,
                   double s1, double* axial) {
  const Vector3d w = o - p0;
  const Vector3d dp = d - d.dot(e) * e, wp = w - w.dot(e) * e;
  const double a = dp.squaredNorm(), b = wp.dot(dp), c = wp.squaredNorm() - r * r;
  const double disc = b * b - a * c;
  if (a <= 0 || disc < 0) return kInf;
  const double sq = std::sqrt(disc);
  for (double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (t <= 1e-9) continue;
    const double s = (w + t * d).dot(e);
    if (s >= s0 && s <= s1) {
      *axial = s;
      return t;
    }
  }
  return kInf;
}

struct Rgb {
  double b = 0, g = 0, r = 0;
  Rgb operator*(double k) const { return {b * k, g * k, r * k}; }
  Rgb operator+(const Rgb& o) const { return {b + o.b, g + o.g, r + o.r}; }
};

}  // namespace

struct ClipRenderer::Impl {
  Scene scene;
  SceneCalibration calibration;
  ClipApparatus apparatus;
  int n_ss;
  int width, height;
  Vector3d eye;                   // camera centre, apparatus frame
  std::vector<Vector3f> rays;     // unit viewing ray of every pixel centre, apparatus frame
  cv::Mat background;             // CV_32FC3
  cv::Mat static_edge;            // CV_8U: 1 where a static boundary crosses the pixel
  double across, along;           // body semi-axes (a in x and z, b in y)
  double rod_radius;              // drawn
  Vector3d rail_dir[2];           // unit axes of the rods (−, +)
  double rail_end;                // axial length of the drawn rods
  Vector3d light;                 // unit, toward the light
  double crossbar_z, crossbar_half_length;
  double foot_y;                  // the feet stand under the rails: y = ±crossbar_x·tan(α/2)
  std::vector<double> tape_axial; // the tape marks' distances from O along the rods, m
  double shadow_softness = 0.006;  // m, half width of the penumbra

  Impl(const Scene& s, const SceneCalibration& c, const ClipApparatus& a, int n)
      : scene(s), calibration(c), apparatus(a), n_ss(n) {}

  Vector3d RayAt(double u, double v) const {
    const int i0 = std::clamp(static_cast<int>(std::floor(u)), 0, width - 2);
    const int j0 = std::clamp(static_cast<int>(std::floor(v)), 0, height - 2);
    const double fu = u - i0, fv = v - j0;  // outside [0, 1] at the border: linear extrapolation
    const Vector3f& r00 = rays[j0 * width + i0];
    const Vector3f& r10 = rays[j0 * width + i0 + 1];
    const Vector3f& r01 = rays[(j0 + 1) * width + i0];
    const Vector3f& r11 = rays[(j0 + 1) * width + i0 + 1];
    const Vector3f top = r00 + static_cast<float>(fu) * (r10 - r00);
    const Vector3f bottom = r01 + static_cast<float>(fu) * (r11 - r01);
    return (top + static_cast<float>(fv) * (bottom - top)).cast<double>().normalized();
  }

  // Ray parameter of the body's surface (centre c), or ∞.
  double HitBody(const Vector3d& o, const Vector3d& d, const Vector3d& c) const {
    const double s = across / along;  // scaling y by s turns the spheroid into a sphere of radius a
    const Vector3d os(o.x() - c.x(), s * (o.y() - c.y()), o.z() - c.z());
    const Vector3d ds(d.x(), s * d.y(), d.z());
    const double qa = ds.squaredNorm(), qb = os.dot(ds), qc = os.squaredNorm() - across * across;
    const double disc = qb * qb - qa * qc;
    if (disc < 0) return kInf;
    const double t = (-qb - std::sqrt(disc)) / qa;
    return t > 1e-9 ? t : kInf;
  }

  // Signed distance of the ray to the body's outline, roughly in pixels (> 0 outside).
  double OutlineDistancePx(const Vector3d& o, const Vector3d& d, const Vector3d& c) const {
    const double s = across / along;
    const Vector3d os(o.x() - c.x(), s * (o.y() - c.y()), o.z() - c.z());
    const Vector3d ds = Vector3d(d.x(), s * d.y(), d.z()).normalized();
    const double along_ray = -os.dot(ds);
    if (along_ray <= 0) return kInf;
    const double dist = (os + along_ray * ds).norm();
    return (dist - across) / along_ray * calibration.camera.fx;
  }

  // Light reaching a table point (1 lit, → 0 in the body's shadow), soft-edged.
  double ShadowFactor(const Vector3d& p, const std::vector<Vector3d>& bodies) const {
    double lit = 1;
    for (const Vector3d& c : bodies) {
      const double s = across / along;
      const Vector3d os(p.x() - c.x(), s * (p.y() - c.y()), p.z() - c.z());
      const Vector3d ls = Vector3d(light.x(), s * light.y(), light.z()).normalized();
      const double t = -os.dot(ls);
      if (t <= 0) continue;
      const double dist = (os + t * ls).norm();
      const double k = std::clamp((dist - across + shadow_softness) / (2 * shadow_softness), 0.0, 1.0);
      lit = std::min(lit, 0.35 + 0.65 * k * k * (3 - 2 * k));
    }
    return lit;
  }

  struct Hit {
    double t = kInf;      // ray parameter (unit ray: distance from the eye, m)
    ObjectId id = kNone;
    double axial = 0;     // along a rod, the crossbar or a foot
    int index = -1;       // which body, rod (0: −y, 1: +y) or foot (0: −y, 1: +y)
  };

  // The first surface the ray from the eye along d meets.
  Hit FirstHit(const Vector3d& d, const std::vector<Vector3d>& bodies) const {
    const Vector3d& o = eye;
    Hit h;
    for (size_t k = 0; k < bodies.size(); ++k) {
      const double t = HitBody(o, d, bodies[k]);
      if (t < h.t) h = {t, kBody, 0, static_cast<int>(k)};
    }
    double s = 0;
    for (int k = 0; k < 2; ++k) {
      const double t = HitCylinder(o, d, Vector3d::Zero(), rail_dir[k], rod_radius, 0.0, rail_end, &s);
      if (t < h.t) h = {t, OnTape(s) ? kTape : k == 0 ? kRodMinus : kRodPlus, s, k};
    }
    {
      const Vector3d p0(apparatus.crossbar_x, 0, crossbar_z);
      const double t = HitCylinder(o, d, p0, Vector3d::UnitY(), apparatus.crossbar_radius, -crossbar_half_length,
                                   crossbar_half_length, &s);
      if (t < h.t) h = {t, kCrossbar, s, -1};
    }
    if (apparatus.feet)
      for (double side : {-1.0, 1.0}) {
        const Vector3d p0(apparatus.crossbar_x, side * foot_y, apparatus.table_z);
        const double t = HitCylinder(o, d, p0, Vector3d::UnitZ(), apparatus.foot_radius, 0.0, crossbar_z - apparatus.table_z, &s);
        if (t < h.t) h = {t, kFoot, s, side > 0 ? 1 : 0};
      }
    if (d.z() < 0) {
      const double t = (apparatus.table_z - o.z()) / d.z();
      if (t < h.t) {
        const Vector3d p = o + t * d;
        h = {t, apparatus.ruler && OnRuler(p.x(), p.y()) ? kRuler : kTable, 0, -1};
      }
    }
    if (d.y() > 0) {
      const double t = (apparatus.wall_y - o.y()) / d.y();
      if (t < h.t) h = {t, kWall, 0, -1};
    }
    return h;
  }

  // Tape at rod length s (ClipApparatus::tape_marks_x, measured along the rod from O).
  bool OnTape(double s) const {
    for (double m : tape_axial)
      if (std::abs(s - m) <= apparatus.tape_width / 2) return true;
    return false;
  }

  Rgb Shade(const Vector3d& d, const std::vector<Vector3d>& bodies, ObjectId* id) const {
    const Hit h = FirstHit(d, bodies);
    *id = h.id;
    const Vector3d p = eye + h.t * d;
    const Vector3d view = -d;
    auto lambert = [&](const Vector3d& n) { return 0.28 + 0.72 * std::max(0.0, n.dot(light)); };
    auto highlight = [&](const Vector3d& n, double shininess) {
      const double nh = std::max(0.0, n.dot((light + view).normalized()));
      return std::pow(nh, shininess);
    };
    auto rod_normal = [&]() {
      const Vector3d& e = rail_dir[h.index];
      return Vector3d((p - h.axial * e).normalized());
    };
    switch (h.id) {
      case kBody: {
        const Vector3d q = p - bodies[h.index];
        const Vector3d n =
            Vector3d(q.x() / (across * across), q.y() / (along * along), q.z() / (across * across)).normalized();
        const Rgb paint{0.10, 0.14, 0.72};
        if (apparatus.body_finish == ClipApparatus::Finish::kFlat) return paint * 0.6;
        const double spec = apparatus.body_finish == ClipApparatus::Finish::kMatte ? 0.0 : 0.75 * highlight(n, 40);
        return paint * lambert(n) + Rgb{spec, spec, spec};
      }
      case kRodMinus:
      case kRodPlus: {
        const Vector3d n = rod_normal();
        const Rgb steel{0.50, 0.50, 0.52};
        const double spec = 0.5 * highlight(n, 25);
        return steel * lambert(n) + Rgb{spec, spec, spec};
      }
      case kTape:  // black vinyl tape: dark, with a dull sheen
        return Rgb{0.035, 0.035, 0.04} * lambert(rod_normal()) + Rgb{1, 1, 1} * (0.04 * highlight(rod_normal(), 10));
      case kCrossbar: {
        const Vector3d n = (p - Vector3d(apparatus.crossbar_x, h.axial, crossbar_z)).normalized();
        return Rgb{0.22, 0.32, 0.42} * lambert(n);
      }
      case kFoot: {
        const Vector3d n = Vector3d(p.x() - apparatus.crossbar_x, p.y() - (h.index ? foot_y : -foot_y), 0).normalized();
        return Rgb{0.22, 0.32, 0.42} * lambert(n);
      }
      case kTable:
      case kRuler: {
        const double lit = lambert(Vector3d::UnitZ()) * ShadowFactor(p, bodies);
        if (h.id == kRuler) return (OnTick(p.x(), p.y()) ? Rgb{0.03, 0.03, 0.03} : Rgb{0.20, 0.62, 0.78}) * lit;
        return Rgb{0.55, 0.68, 0.80} * (TableTexture(p.x(), p.y()) * lit);
      }
      case kWall:
        return Rgb{0.80, 0.82, 0.80} * (0.75 + 0.1 * std::tanh(p.z()));
      default:
        return Rgb{};
    }
  }

  // Average of n×n samples spread over the pixel (u, v).
  Rgb Supersample(int u, int v, const std::vector<Vector3d>& bodies) const {
    Rgb sum;
    ObjectId id;
    for (int j = 0; j < n_ss; ++j)
      for (int i = 0; i < n_ss; ++i)
        sum = sum + Shade(RayAt(u + (i + 0.5) / n_ss - 0.5, v + (j + 0.5) / n_ss - 0.5), bodies, &id);
    return sum * (1.0 / (n_ss * n_ss));
  }

  void RenderBackground() {
    background.create(height, width, CV_32FC3);
    cv::Mat ids(height, width, CV_8U);
    const std::vector<Vector3d> none;
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) {
        ObjectId id;
        const Rgb c = Shade(rays[v * width + u].cast<double>().normalized(), none, &id);
        background.at<cv::Vec3f>(v, u) = cv::Vec3f(c.b, c.g, c.r);
        ids.at<std::uint8_t>(v, u) = id;
      }
    static_edge = cv::Mat::zeros(height, width, CV_8U);
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) {
        const std::uint8_t id = ids.at<std::uint8_t>(v, u);
        bool edge = false;
        for (int dv = -1; dv <= 1 && !edge; ++dv)
          for (int du = -1; du <= 1 && !edge; ++du) {
            const int uu = u + du, vv = v + dv;
            if (uu >= 0 && vv >= 0 && uu < width && vv < height && ids.at<std::uint8_t>(vv, uu) != id) edge = true;
          }
        if (id == kRuler) edge = true;  // the ticks, 1 mm wide, are finer than a pixel
        if (edge) {
          static_edge.at<std::uint8_t>(v, u) = 1;
          const Rgb c = Supersample(u, v, none);
          background.at<cv::Vec3f>(v, u) = cv::Vec3f(c.b, c.g, c.r);
        }
      }
  }

  // Pixel box holding the body and its shadow for every centre (empty rect if off the frame).
  cv::Rect DynamicBox(const std::vector<Vector3d>& bodies) const {
    std::vector<Vector3d> corners;
    const double rho = std::max(across, along) * 1.05;
    const double reach = rho + 2 * shadow_softness;
    for (const Vector3d& c : bodies) {
      for (int k = 0; k < 8; ++k)
        corners.push_back(c + rho * Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1));
      const Vector3d s = c - (c.z() - apparatus.table_z) / light.z() * light;  // shadow centre on the table
      const double spread = reach / light.z();
      for (int k = 0; k < 4; ++k)
        corners.push_back(s + Vector3d(k & 1 ? spread : -spread, k & 2 ? spread : -spread, 0));
    }
    // Only points in front of the camera can be projected; the renderer's scenes keep them there.
    const Eigen::Matrix3d& R = calibration.pose.rotation;
    const Vector3d& tr = calibration.pose.translation;
    double u0 = kInf, v0 = kInf, u1 = -kInf, v1 = -kInf;
    std::vector<Vector3d> in_front;
    for (const Vector3d& p : corners)
      if ((R * p + tr).z() > 1e-3) in_front.push_back(p);
    for (const Vector2d& q : ProjectApparatusPoints(calibration.camera, calibration.pose, in_front)) {
      u0 = std::min(u0, q.x()), u1 = std::max(u1, q.x());
      v0 = std::min(v0, q.y()), v1 = std::max(v1, q.y());
    }
    if (!(u1 >= u0)) return {};
    const int margin = 3;
    const int x0 = std::max(0, static_cast<int>(std::floor(u0)) - margin);
    const int y0 = std::max(0, static_cast<int>(std::floor(v0)) - margin);
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(u1)) + margin);
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(v1)) + margin);
    if (x1 < x0 || y1 < y0) return {};
    return cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  }
};

ClipRenderer::ClipRenderer(const Scene& scene, const SceneCalibration& calibration, const ClipApparatus& apparatus,
                           int supersampling)
    : impl_(std::make_unique<Impl>(scene, calibration, apparatus, supersampling)) {
  ValidateIntrinsics(calibration.camera, "camera");
  if (scene.body().kind == BodyKind::kDoubleCone)
    throw InputError("body", "the synthetic clip draws a sphere or a spheroid, not a double cone");
  if (supersampling < 1 || supersampling > 16) throw InputError("supersampling", "must be in 1..16");
  Impl& m = *impl_;
  m.width = calibration.camera.width;
  m.height = calibration.camera.height;
  m.eye = CameraCentre(calibration.pose);
  m.across = scene.body().across;
  m.along = scene.body().along;
  m.rod_radius = std::max(scene.rod_radius(), apparatus.min_rod_radius);
  const double T = scene.rails().tan_half_alpha, B = scene.rails().tan_theta;
  m.rail_dir[0] = Vector3d(1, -T, B).normalized();
  m.rail_dir[1] = Vector3d(1, T, B).normalized();
  m.rail_end = (apparatus.crossbar_x + 0.04) * Vector3d(1, T, B).norm();
  m.light = Vector3d(-0.35, -0.45, 1.0).normalized();
  m.crossbar_z = apparatus.crossbar_x * B - m.rod_radius - apparatus.crossbar_radius;
  m.crossbar_half_length = apparatus.crossbar_x * T + 0.06;
  m.foot_y = apparatus.crossbar_x * T;
  for (double x : apparatus.tape_marks_x) m.tape_axial.push_back(x * Vector3d(1, T, B).norm());

  std::vector<Vector2d> pixels;
  pixels.reserve(static_cast<size_t>(m.width) * m.height);
  for (int v = 0; v < m.height; ++v)
    for (int u = 0; u < m.width; ++u) pixels.emplace_back(u, v);
  const std::vector<Vector2d> normalised = UndistortPixels(calibration.camera, pixels);
  const Eigen::Matrix3d to_apparatus = calibration.pose.rotation.transpose();
  m.rays.resize(pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k)
    m.rays[k] = (to_apparatus * Vector3d(normalised[k].x(), normalised[k].y(), 1.0)).normalized().cast<float>();
  m.RenderBackground();
}

ClipRenderer::~ClipRenderer() = default;

const SceneCalibration& ClipRenderer::calibration() const { return impl_->calibration; }

cv::Mat ClipRenderer::RenderLinear(const std::vector<Vector2d>& centres) const {
  const Impl& m = *impl_;
  cv::Mat out = m.background.clone();
  if (centres.empty()) return out;
  std::vector<Vector3d> bodies;
  for (const Vector2d& c : centres) bodies.emplace_back(c.x(), 0.0, c.y());
  const cv::Rect box = m.DynamicBox(bodies);
  const double near_px = 1.5;
  std::vector<Vector3d> one(1);
  for (int v = box.y; v < box.y + box.height; ++v)
    for (int u = box.x; u < box.x + box.width; ++u) {
      const Vector3d d = m.rays[v * m.width + u].cast<double>().normalized();
      const bool static_edge = m.static_edge.at<std::uint8_t>(v, u) != 0;
      Rgb sum;
      for (const Vector3d& c : bodies) {
        one[0] = c;
        if (static_edge || std::abs(m.OutlineDistancePx(m.eye, d, c)) < near_px) {
          sum = sum + m.Supersample(u, v, one);
        } else {
          ObjectId id;
          sum = sum + m.Shade(d, one, &id);
        }
      }
      sum = sum * (1.0 / bodies.size());
      out.at<cv::Vec3f>(v, u) = cv::Vec3f(sum.b, sum.g, sum.r);
    }
  return out;
}

double ClipRenderer::Visibility(double x, double z) const {
  const Impl& m = *impl_;
  // Outline points: generators of the tangent cone from the eye (in the space where the body is a
  // sphere of radius a), mapped back.
  const double s = m.across / m.along;
  const Vector3d c(x, 0, z);
  const Vector3d eye_s(m.eye.x(), s * m.eye.y(), m.eye.z());
  const Vector3d axis = c - eye_s;
  const double dist = axis.norm();
  if (dist <= m.across) return 0;
  const Vector3d w = axis / dist;
  const Vector3d e1 = w.unitOrthogonal(), e2 = w.cross(e1);
  const double sin_b = m.across / dist, cos_b = std::sqrt(1 - sin_b * sin_b);
  const int n = 64;
  std::vector<Vector3d> points;
  for (int k = 0; k < n; ++k) {
    const double phi = 2 * M_PI * k / n;
    const Vector3d g = cos_b * w + sin_b * (std::cos(phi) * e1 + std::sin(phi) * e2);
    const Vector3d ts = eye_s + g * (dist * cos_b);
    points.emplace_back(ts.x(), ts.y() / s, ts.z());
  }
  const std::vector<Vector2d> image = ProjectApparatusPoints(m.calibration.camera, m.calibration.pose, points);
  int visible = 0;
  for (int k = 0; k < n; ++k) {
    if (image[k].x() < 0 || image[k].y() < 0 || image[k].x() > m.width - 1 || image[k].y() > m.height - 1) continue;
    // Hidden where the apparatus (a rod, the crossbar, a foot) stands in front of the outline.
    const Vector3d to = points[k] - m.eye;
    const double reach = to.norm();
    visible += !(m.FirstHit(to / reach, {}).t < reach - 1e-6);
  }
  return static_cast<double>(visible) / n;
}

bool ClipRenderer::Sees(const Vector3d& point, const std::vector<Vector2d>& centres, double reach) const {
  const Impl& m = *impl_;
  if ((m.calibration.pose.rotation * point + m.calibration.pose.translation).z() <= 1e-3) return false;
  const Vector2d pixel = ProjectApparatusPoint(m.calibration.camera, m.calibration.pose, point);
  if (!(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= m.width - 1 && pixel.y() <= m.height - 1)) return false;
  std::vector<Vector3d> bodies;
  for (const Vector2d& c : centres) bodies.emplace_back(c.x(), 0.0, c.y());
  const Vector3d d = (point - m.eye).normalized();
  return (m.eye + m.FirstHit(d, bodies).t * d - point).norm() <= reach;
}

cv::Mat ToFrame8(const cv::Mat& linear, double gain, double noise_sigma, cv::RNG& rng) {
  // The sRGB curve, tabulated on 2^16 steps of the linear value (its largest step, at the dark
  // end, is 0.05 of an 8-bit level).
  static const std::vector<float> encode = [] {
    std::vector<float> t(65536);
    for (size_t k = 0; k < t.size(); ++k) t[k] = static_cast<float>(255.0 * SrgbEncode(k / 65535.0));
    return t;
  }();
  cv::Mat scaled(linear.size(), CV_32FC3);
  for (int y = 0; y < linear.rows; ++y) {
    const cv::Vec3f* in = linear.ptr<cv::Vec3f>(y);
    cv::Vec3f* out = scaled.ptr<cv::Vec3f>(y);
    for (int x = 0; x < linear.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double v = std::clamp(static_cast<double>(in[x][c]) * gain, 0.0, 1.0);
        out[x][c] = encode[static_cast<size_t>(std::lround(v * 65535))];
      }
  }
  if (noise_sigma > 0) {
    cv::Mat noise(scaled.size(), CV_32FC3);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    scaled += noise;
  }
  cv::Mat out;
  scaled.convertTo(out, CV_8UC3);  // rounds and saturates
  return out;
}

std::vector<ClipTruth> RenderClip(const ClipRenderer& renderer, const Motion& motion, const ClipSettings& s,
                                  const std::string& video_path) {
  if (s.frames < 1) throw InputError("frames", "must be >= 1");
  if (!(s.fps > 0 && std::isfinite(s.fps))) throw InputError("fps", "must be > 0");
  if (s.blur_samples < 1) throw InputError("blur_samples", "must be >= 1");
  if (!(s.exposure >= 0 && s.exposure <= 1.0 / s.fps)) throw InputError("exposure", "must be in [0, 1/fps]");
  if (!(s.noise_sigma >= 0) || !(s.flicker >= 0)) throw InputError("noise/flicker", "must be >= 0");
  const std::string ext = std::filesystem::path(video_path).extension().string();
  int fourcc;
  if (ext == ".mp4") fourcc = cv::VideoWriter::fourcc('a', 'v', 'c', '1');
  else if (ext == ".avi" || ext == ".mkv") fourcc = cv::VideoWriter::fourcc('F', 'F', 'V', '1');
  else throw InputError(video_path, "unknown video extension (use .mp4 for H.264, .avi or .mkv for lossless FFV1)");
  const SceneCalibration& cal = renderer.calibration();
  // Write to a temporary name in the same folder, then rename: never a half-written clip.
  const std::string temporary = video_path + ".partial" + ext;
  cv::VideoWriter writer(temporary, cv::CAP_FFMPEG, fourcc, s.fps, cv::Size(cal.camera.width, cal.camera.height));
  if (!writer.isOpened()) throw std::runtime_error(video_path + ": cannot open the video writer");
  cv::RNG rng(s.seed);
  std::vector<ClipTruth> truth;
  const double end = motion.end_time();
  auto centre_at = [&](double clip_time, Vector2d* c) {
    const double tm = std::max(0.0, clip_time - s.release_time);
    if (tm > end) return false;
    const MotionSample m = motion.At(tm);
    *c = Vector2d(m.x, m.z);
    return true;
  };
  for (int f = 0; f < s.frames; ++f) {
    ClipTruth row;
    row.frame = f;
    row.t = f / s.fps;
    Vector2d c;
    // Present only when the motion lasts the whole exposure: a body that leaves the rails'
    // model during it (falls off, reaches O) is not drawn, rather than drawn half-blurred.
    row.present = centre_at(row.t, &c) && (s.blur_samples == 1 || centre_at(row.t + s.exposure / 2, &c));
    if (row.present) centre_at(row.t, &c);
    std::vector<Vector2d> centres;
    if (row.present) {
      row.x = c.x();
      row.z = c.y();
      const Vector2d uv = ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(c.x(), 0, c.y()));
      row.u = uv.x();
      row.v = uv.y();
      row.visibility = renderer.Visibility(c.x(), c.y());
      if (s.blur_samples == 1) {
        centres.push_back(c);
      } else {
        for (int j = 0; j < s.blur_samples; ++j) {
          Vector2d cj;
          if (centre_at(row.t + s.exposure * ((j + 0.5) / s.blur_samples - 0.5), &cj)) centres.push_back(cj);
        }
      }
    }
    const double gain = s.flicker > 0 ? 1.0 + rng.gaussian(s.flicker) : 1.0;
    writer.write(ToFrame8(renderer.RenderLinear(centres), gain, s.noise_sigma, rng));
    truth.push_back(row);
  }
  writer.release();
  std::error_code ec;
  std::filesystem::rename(temporary, video_path, ec);
  if (ec) throw std::runtime_error(video_path + ": cannot rename the finished clip into place: " + ec.message());
  return truth;
}

void WriteClipTruthCsv(const std::string& path, const std::vector<ClipTruth>& truth) {
  std::ostringstream out;
  out << "frame,t,x,z,u,v,visibility\n";
  char line[256];
  for (const ClipTruth& r : truth) {
    if (r.present)
      std::snprintf(line, sizeof line, "%d,%.9f,%.6f,%.6f,%.6f,%.6f,%.4f\n", r.frame, r.t, r.x * 1e3, r.z * 1e3, r.u, r.v,
                    r.visibility);
    else
      std::snprintf(line, sizeof line, "%d,%.9f,,,,,0\n", r.frame, r.t);
    out << line;
  }
  WriteFileAtomically(path, out.str());
}

SceneCalibration SideViewCamera(int width, int height, double target_x, double target_z) {
  SceneCalibration cal;
  CameraIntrinsics& k = cal.camera;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 1300.0 * width / 1280.0;
  k.cx = (width - 1) / 2.0 + 3.7 * width / 1280.0;
  k.cy = (height - 1) / 2.0 - 2.9 * width / 1280.0;
  k.distortion = {-0.10, 0.02, 0.0, 0.0, 0.0};
  const Vector3d eye(target_x + 0.02, -1.30, target_z + 0.30);
  const Vector3d target(target_x, 0.0, target_z);
  const Vector3d forward = (target - eye).normalized();             // camera z
  const Vector3d right = Vector3d(0, 0, -1).cross(forward).normalized();  // camera x
  const Vector3d down = forward.cross(right);                        // camera y
  cal.pose.rotation.row(0) = right.transpose();
  cal.pose.rotation.row(1) = down.transpose();
  cal.pose.rotation.row(2) = forward.transpose();
  cal.pose.translation = -cal.pose.rotation * eye;
  return cal;
}

ClipSetup TrialClipSetup(int width, int height, double D, double mu, double band_fraction) {
  ClipSetup setup = DefaultClipSetup(width, height);
  setup.scene = Scene(setup.scene.body(), Rails::FromApparatus(1.0, 0.1, D, LConvention::kHorizontal),
                      setup.scene.rod_radius());
  const std::optional<RestBand> band = setup.scene.Rest(mu);
  if (!band || !setup.scene.x_eq()) throw InputError("mu", "the trial's scene has no rest band for this mu");
  setup.x0 = band->high + band_fraction * (band->high - *setup.scene.x_eq());
  return setup;
}

ClipSetup DefaultClipSetup(int width, int height) {
  const double L = 1.0, H = 0.1, D = 0.15;
  const Scene scene(Body::Sphere(0.0254), Rails::FromApparatus(L, H, D, LConvention::kHorizontal), 0.004);
  ClipApparatus apparatus;
  apparatus.crossbar_x = L;
  const double x0 = 0.97 * *scene.x_eq();
  return {scene, SideViewCamera(width, height, 0.5, 0.02), apparatus, x0};
}

}  // namespace uphill
