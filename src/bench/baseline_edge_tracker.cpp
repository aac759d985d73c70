// The baseline edge-fit tracker (baseline_edge_tracker.hpp): rays, gradient edges, one Ceres fit.
#include "bench/baseline_edge_tracker.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <deque>
#include <opencv2/imgproc.hpp>

#include "model/input_error.hpp"
#include "vision/ball_tracker.hpp"
#include "vision/camera.hpp"

namespace uphill::bench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kStep = 0.5;              // px between profile samples
constexpr double kNarrowHalfWidth = 2.5;   // px, second pass around the first fit
constexpr double kInlierPx = 1.0;          // |residual| below this: inlier
constexpr double kLossScalePx = 0.5;       // Cauchy scale
constexpr double kBiasPriorPx = 0.5;       // the edge-bias parameter's prior width

// Residual of one edge point, in pixels: angle between its viewing ray and the centre's
// direction minus the outline's half angle, minus the edge bias (all in the space where the body
// is a sphere of radius a).
struct OutlineResidual {
  Vector3d ray;  // scaled-space direction of the edge point's viewing ray (unit)
  Vector3d eye;  // scaled-space camera centre
  double a, s, px_per_rad;
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const T c[3] = {p[0] - eye.x(), T(-eye.y()), p[1] - eye.z()};  // C has y = 0, unchanged by scaling
    const T norm = ceres::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const T cross[3] = {ray.y() * c[2] - ray.z() * c[1], ray.z() * c[0] - ray.x() * c[2],
                        ray.x() * c[1] - ray.y() * c[0]};
    const T sin_part = ceres::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    const T cos_part = ray.x() * c[0] + ray.y() * c[1] + ray.z() * c[2];
    const T angle = ceres::atan2(sin_part, cos_part);
    residual[0] = (angle - ceres::asin(T(a) / norm)) * px_per_rad - p[2];
    return true;
  }
};

struct BiasPrior {
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = p[2] / kBiasPriorPx;
    return true;
  }
};

double Bilinear(const cv::Mat& img, double x, double y) {
  const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
  const double fx = x - i, fy = y - j;
  const float* r0 = img.ptr<float>(j);
  const float* r1 = img.ptr<float>(j + 1);
  const double top = r0[i] + fx * (r0[i + 1] - r0[i]);
  const double bottom = r1[i] + fx * (r1[i + 1] - r1[i]);
  return top + fy * (bottom - top);
}

struct Fit {
  bool ok = false;
  double x = 0, z = 0;
  int edge_points = 0, inliers = 0, attempted = 0;
  double rms_px = 0, contrast = 0;
};

}  // namespace

struct BaselineEdgeTracker::Impl {
  Scene scene;
  SceneCalibration cal;
  BaselineOptions options;
  double a, s;          // body semi-axis across, scaling of y that makes it a sphere
  Vector3d eye, eye_s;  // camera centre, and in the scaled space
  Eigen::Matrix3d to_apparatus;
  cv::Mat occluder;     // CV_8U: the near rail's band (outline points there are not used)
  int polarity = 0;     // sign of the grey step from inside to outside the body; 0: unknown
  std::deque<std::pair<long, Vector2d>> history;  // last found (frame, (x, z))
  long frame_index = -1;
  double x_lo, x_hi;    // searchable part of the path

  Impl(const Scene& sc, const SceneCalibration& c, const BaselineOptions& o) : scene(sc), cal(c), options(o) {}

  // Tangent points of the cone from the eye (scaled space, mapped back), n of them.
  std::vector<Vector3d> OutlinePoints(double x, double z, int n) const {
    const Vector3d c(x, 0, z);
    const Vector3d axis = c - eye_s;
    const double dist = axis.norm();
    const Vector3d w = axis / dist;
    // A fixed reference direction keeps point k at the same place on the outline frame to frame.
    const Vector3d e1 = w.cross(Vector3d::UnitY()).normalized(), e2 = w.cross(e1);
    const double sin_b = std::min(1.0, a / dist), cos_b = std::sqrt(1 - sin_b * sin_b);
    std::vector<Vector3d> out;
    out.reserve(n);
    for (int k = 0; k < n; ++k) {
      const double phi = 2 * M_PI * k / n;
      const Vector3d ts = eye_s + (cos_b * w + sin_b * (std::cos(phi) * e1 + std::sin(phi) * e2)) * (dist * cos_b);
      out.emplace_back(ts.x(), ts.y() / s, ts.z());
    }
    return out;
  }

  bool InFront(double x, double z) const {
    return (cal.pose.rotation * Vector3d(x, 0, z) + cal.pose.translation).z() > 2 * a &&
           (Vector3d(x, 0, z) - eye).norm() > 2 * std::max(a, a / s);
  }

  // One pass: edges along rays across the outline predicted at (x, z), then the Ceres fit.
  Fit FitOnce(const cv::Mat& frame, double x, double z, double half_width) {
    Fit fit;
    if (!InFront(x, z)) return fit;
    const int n = options.outline_points;
    std::vector<Vector3d> points = OutlinePoints(x, z, n);
    points.emplace_back(x, 0, z);
    const std::vector<Vector2d> image = ProjectApparatusPoints(cal.camera, cal.pose, points);
    const Vector2d q = image.back();
    // Region of interest: all search segments, plus the smoothing kernel's reach.
    double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
    for (int k = 0; k < n; ++k) {
      u0 = std::min(u0, image[k].x()), u1 = std::max(u1, image[k].x());
      v0 = std::min(v0, image[k].y()), v1 = std::max(v1, image[k].y());
    }
    const double pad = half_width + 6;
    const cv::Rect full(0, 0, frame.cols, frame.rows);
    const cv::Rect roi = cv::Rect(cv::Point(static_cast<int>(std::floor(u0 - pad)), static_cast<int>(std::floor(v0 - pad))),
                                  cv::Point(static_cast<int>(std::ceil(u1 + pad)), static_cast<int>(std::ceil(v1 + pad)))) &
                         full;
    if (roi.width < 8 || roi.height < 8) return fit;
    cv::Mat grey, smooth;
    if (frame.channels() == 3) cv::cvtColor(frame(roi), grey, cv::COLOR_BGR2GRAY);
    else grey = frame(roi);
    grey.convertTo(smooth, CV_32F);
    cv::GaussianBlur(smooth, smooth, cv::Size(7, 7), 1.0);

    const int samples = 2 * static_cast<int>(std::ceil(half_width / kStep)) + 1;
    const double start = -(samples / 2) * kStep;
    std::vector<double> profile(samples);
    std::vector<Vector2d> edges;
    std::vector<double> contrasts;
    std::vector<int> signs;
    for (int k = 0; k < n; ++k) {
      const Vector2d radial = image[k] - q;
      if (radial.norm() < 1) continue;
      const Vector2d dir = radial.normalized();
      const Vector2d first = image[k] + start * dir, last = image[k] - start * dir;
      // Inside the region (with one pixel for the interpolation) and the frame.
      auto inside = [&](const Vector2d& p) {
        return p.x() >= roi.x + 3 && p.y() >= roi.y + 3 && p.x() <= roi.x + roi.width - 4 &&
               p.y() <= roi.y + roi.height - 4;
      };
      if (!inside(first) || !inside(last)) continue;
      bool hidden = false;
      for (int m = 0; m <= 4 && !hidden; ++m) {
        const Vector2d p = first + (last - first) * (m / 4.0);
        hidden = occluder.at<std::uint8_t>(static_cast<int>(std::lround(p.y())), static_cast<int>(std::lround(p.x()))) != 0;
      }
      if (hidden) continue;
      ++fit.attempted;
      for (int i = 0; i < samples; ++i) {
        const Vector2d p = first + (i * kStep) * dir;
        profile[i] = Bilinear(smooth, p.x() - roi.x, p.y() - roi.y);
      }
      // Gradient (outward) and its strongest peak of the expected polarity.
      int best = -1;
      double best_g = 0;
      std::vector<double> g(samples, 0.0);
      for (int i = 1; i + 1 < samples; ++i) {
        g[i] = (profile[i + 1] - profile[i - 1]) / (2 * kStep);
        const double signed_g = polarity == 0 ? std::abs(g[i]) : polarity * g[i];
        if (i >= 2 && i + 2 < samples && signed_g > best_g) best_g = signed_g, best = i;
      }
      if (best < 0 || best_g < 2.0) continue;
      // Centroid of the gradient above half its peak: the middle of the edge's ramp. For a sharp
      // edge that is the peak; for a motion-blurred one (a ramp as long as the blur, with a flat
      // gradient) it is the edge at mid-exposure, where a peak finder would wander.
      const int sign = g[best] > 0 ? 1 : -1;
      const double half = 0.5 * std::abs(g[best]);
      int lo = best, hi = best;
      while (lo > 1 && sign * g[lo - 1] > half) --lo;
      while (hi + 2 < samples && sign * g[hi + 1] > half) ++hi;
      double weight = 0, moment = 0;
      for (int i = lo; i <= hi; ++i) {
        const double w = sign * g[i] - half;
        weight += w;
        moment += w * i;
      }
      const double along = start + (moment / weight) * kStep;
      edges.push_back(image[k] + along * dir);
      contrasts.push_back(profile[std::min(samples - 1, hi + 3)] - profile[std::max(0, lo - 3)]);
      signs.push_back(g[best] > 0 ? 1 : -1);
    }
    fit.edge_points = static_cast<int>(edges.size());
    if (fit.edge_points < 8) return fit;
    {
      std::vector<double> c = contrasts;
      for (double& v : c) v = std::abs(v);
      std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
      fit.contrast = c[c.size() / 2];
    }

    // Viewing rays of the edge points, in the scaled space.
    const std::vector<Vector2d> normalised = UndistortPixels(cal.camera, edges);
    const double px_per_rad =
        cal.camera.fx * (Vector3d(x, 0, z) - eye_s).norm() / (Vector3d(x, 0, z) - eye).norm();
    double p[3] = {x, z, 0.0};
    ceres::CauchyLoss loss(kLossScalePx);  // one loss for all residuals, owned here
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    for (const Vector2d& m : normalised) {
      Vector3d r = to_apparatus * Vector3d(m.x(), m.y(), 1.0);
      r.y() *= s;
      auto* cost = new ceres::AutoDiffCostFunction<OutlineResidual, 1, 3>(
          new OutlineResidual{r.normalized(), eye_s, a, s, px_per_rad});
      problem.AddResidualBlock(cost, &loss, p);
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPrior, 1, 3>(new BiasPrior), nullptr, p);
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver.max_num_iterations = 30;
    solver.num_threads = 1;
    solver.logging_type = ceres::SILENT;
    solver.function_tolerance = 1e-12;
    solver.parameter_tolerance = 1e-12;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !InFront(p[0], p[1])) return fit;

    double sum2 = 0;
    int votes = 0;
    OutlineResidual check{Vector3d::Zero(), eye_s, a, s, px_per_rad};
    for (size_t k = 0; k < normalised.size(); ++k) {
      Vector3d r = to_apparatus * Vector3d(normalised[k].x(), normalised[k].y(), 1.0);
      r.y() *= s;
      check.ray = r.normalized();
      double res = 0;
      check(p, &res);
      if (std::abs(res) < kInlierPx) {
        ++fit.inliers;
        sum2 += res * res;
        votes += signs[k];
      }
    }
    fit.ok = fit.inliers >= 3;
    fit.x = p[0];
    fit.z = p[1];
    fit.rms_px = fit.inliers ? std::sqrt(sum2 / fit.inliers) : 0;
    if (polarity == 0 && fit.inliers > 0) polarity = votes >= 0 ? 1 : -1;
    return fit;
  }

  bool Accept(const Fit& f) const {
    return f.ok && f.inliers >= options.min_inlier_fraction * options.outline_points &&
           f.contrast >= options.min_contrast;
  }

  // Wide search around the guess; a second, narrow one around the first fit when the guess was
  // off by more than a pixel or many edges were outliers (a wide window may have caught an edge
  // that is not the body's). Any point of the outline constrains the fit, so rays cast from a
  // centre a fraction of a pixel off do not need casting again.
  Fit Measure(const cv::Mat& frame, double x, double z, double half_width) {
    Fit first = FitOnce(frame, x, z, half_width);
    if (!first.ok) return first;
    const Vector2d moved = ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(first.x, 0, first.z)) -
                           ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(x, 0, z));
    if (moved.norm() < 1.0 && first.inliers >= 0.9 * first.edge_points) return first;
    Fit second = FitOnce(frame, first.x, first.z, kNarrowHalfWidth);
    return second.ok ? second : first;
  }

  // Search along the centre path: the candidate whose predicted outline shows the strongest
  // consistent step (median over the outline, so partial occlusion does not matter).
  std::optional<Vector2d> Acquire(const cv::Mat& frame) {
    cv::Mat grey, smooth;
    if (frame.channels() == 3) cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    else grey = frame;
    grey.convertTo(smooth, CV_32F);
    cv::GaussianBlur(smooth, smooth, cv::Size(5, 5), 1.0);
    const int n = 32;
    const int candidates = 600;
    double best_score = 0, best_x = 0;
    std::vector<Vector3d> points;
    std::vector<double> xs;
    for (int i = 0; i < candidates; ++i) {
      const double xc = x_lo + (x_hi - x_lo) * (i + 0.5) / candidates;
      const double zc = scene.At(xc).z;
      if (!InFront(xc, zc)) continue;
      const std::vector<Vector3d> outline = OutlinePoints(xc, zc, n);
      points.insert(points.end(), outline.begin(), outline.end());
      points.emplace_back(xc, 0, zc);
      xs.push_back(xc);
    }
    if (xs.empty()) return std::nullopt;
    const std::vector<Vector2d> image = ProjectApparatusPoints(cal.camera, cal.pose, points);
    std::vector<double> steps(n);
    for (size_t c = 0; c < xs.size(); ++c) {
      const Vector2d* pts = &image[c * (n + 1)];
      const Vector2d q = pts[n];
      int used = 0;
      for (int k = 0; k < n; ++k) {
        const Vector2d dir = (pts[k] - q).normalized();
        const Vector2d out = pts[k] + 2.0 * dir, in = pts[k] - 2.0 * dir;
        const bool ok = std::min({out.x(), in.x(), out.y(), in.y()}) >= 1 && std::max(out.x(), in.x()) < smooth.cols - 2 &&
                        std::max(out.y(), in.y()) < smooth.rows - 2;
        if (!ok) continue;
        const double step = Bilinear(smooth, out.x(), out.y()) - Bilinear(smooth, in.x(), in.y());
        steps[used++] = polarity == 0 ? step : polarity * step;
      }
      if (used < n / 2) continue;
      // Both polarities allowed while unknown: the median of the signed steps must be strong.
      std::nth_element(steps.begin(), steps.begin() + used / 2, steps.begin() + used);
      const double median = steps[used / 2];
      const double score = polarity == 0 ? std::abs(median) : median;
      if (score > best_score) best_score = score, best_x = xs[c];
    }
    if (best_score < options.min_contrast) return std::nullopt;
    return Vector2d(best_x, scene.At(best_x).z);
  }

  BaselineObservation Observe(const Fit& f, double quality_scale = 1.0) const {
    BaselineObservation o;
    o.found = true;
    o.x = f.x;
    o.z = f.z;
    const Vector2d uv = ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(f.x, 0, f.z));
    o.u = uv.x();
    o.v = uv.y();
    const std::vector<Vector3d> outline = OutlinePoints(f.x, f.z, 32);
    double sum = 0;
    for (const Vector2d& p : ProjectApparatusPoints(cal.camera, cal.pose, outline)) sum += (p - uv).norm();
    o.radius_px = sum / 32;
    o.edge_points = f.edge_points;
    o.inliers = f.inliers;
    o.rms_px = f.rms_px;
    const double fraction = std::min(1.0, static_cast<double>(f.inliers) / options.outline_points);
    o.quality = quality_scale * fraction * std::exp(-f.rms_px * f.rms_px / (2 * 0.25));
    return o;
  }
};

BaselineEdgeTracker::BaselineEdgeTracker(const Scene& scene, const SceneCalibration& calibration, const BaselineOptions& options)
    : impl_(std::make_unique<Impl>(scene, calibration, options)) {
  ValidateIntrinsics(calibration.camera, "camera");
  const Body& body = scene.body();
  if (body.kind == BodyKind::kDoubleCone)
    throw InputError("body", kDoubleConeRefusal);
  if (options.outline_points < 16 || options.outline_points > 1024)
    throw InputError("outline_points", "must be in 16..1024");
  if (!(options.search_half_width_px >= 2 && options.search_half_width_px <= 200))
    throw InputError("search_half_width_px", "must be in [2, 200] px");
  Impl& m = *impl_;
  m.a = body.across;
  m.s = body.across / body.along;
  m.eye = CameraCentre(calibration.pose);
  m.eye_s = Vector3d(m.eye.x(), m.s * m.eye.y(), m.eye.z());
  m.to_apparatus = calibration.pose.rotation.transpose();
  const double span = scene.x_max() - scene.x_low();
  m.x_lo = scene.x_low() + 1e-6 * span;
  m.x_hi = scene.x_max() - 1e-6 * span;

  // The near rail (on the camera's side) in front of the body: its band in the image, widened
  // by 2.5 px for the smoothing and the edge search.
  m.occluder = cv::Mat::zeros(calibration.camera.height, calibration.camera.width, CV_8U);
  const double rod = scene.rod_radius() > 0 ? scene.rod_radius() : options.rail_radius;
  const double side = m.eye.y() < 0 ? -1.0 : 1.0;
  const Rails& rails = scene.rails();
  const Vector3d axis(1, side * rails.tan_half_alpha, rails.tan_theta);
  std::vector<cv::Point> polyline;
  double max_halfwidth = 0;
  const double x_end = 1.5 * scene.x_max() + 0.2;
  for (int i = 0; i <= 400; ++i) {
    const Vector3d p = axis * (x_end * i / 400.0);
    const Vector3d pc = calibration.pose.rotation * p + calibration.pose.translation;
    if (pc.z() <= 0.05) continue;
    const Vector2d q = ProjectCameraPoint(calibration.camera, pc);
    if (std::abs(q.x()) > 1e5 || std::abs(q.y()) > 1e5) continue;
    polyline.emplace_back(static_cast<int>(std::lround(q.x() * 16)), static_cast<int>(std::lround(q.y() * 16)));
    max_halfwidth = std::max(max_halfwidth, rod * calibration.camera.fx / pc.z());
  }
  if (polyline.size() >= 2)
    cv::polylines(m.occluder, polyline, false, cv::Scalar(1),
                  std::max(1, static_cast<int>(std::ceil(2 * (max_halfwidth + 2.5)))), cv::LINE_8, 4);
}

BaselineEdgeTracker::~BaselineEdgeTracker() = default;
BaselineEdgeTracker::BaselineEdgeTracker(BaselineEdgeTracker&&) noexcept = default;

std::vector<Vector2d> BaselineEdgeTracker::Outline(double x, double z, int n) const {
  return ProjectApparatusPoints(impl_->cal.camera, impl_->cal.pose, impl_->OutlinePoints(x, z, n));
}

BaselineObservation BaselineEdgeTracker::Track(const cv::Mat& frame) {
  Impl& m = *impl_;
  if (frame.empty() || frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3))
    throw InputError("frame", "must be an 8-bit grey or BGR image");
  if (frame.cols != m.cal.camera.width || frame.rows != m.cal.camera.height)
    throw InputError("frame", "is " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                                  " px but the camera calibration is for " + std::to_string(m.cal.camera.width) + "x" +
                                  std::to_string(m.cal.camera.height));
  const long f = ++m.frame_index;
  // Drop history that is too old to predict from.
  while (!m.history.empty() && f - m.history.back().first > 5) m.history.clear();

  if (!m.history.empty()) {
    const auto& h = m.history;
    const size_t n = h.size();
    Vector2d pred = h[n - 1].second;
    double step_px = 0;
    if (n >= 3 && h[n - 1].first - h[n - 3].first == 2 && f - h[n - 1].first == 1) {
      pred = 3 * h[n - 1].second - 3 * h[n - 2].second + h[n - 3].second;
    } else if (n >= 2) {
      const double k = static_cast<double>(f - h[n - 1].first) / (h[n - 1].first - h[n - 2].first);
      pred = h[n - 1].second + k * (h[n - 1].second - h[n - 2].second);
    }
    if (n >= 2) {
      const Vector3d c(h[n - 1].second.x(), 0, h[n - 1].second.y());
      step_px = (h[n - 1].second - h[n - 2].second).norm() * m.cal.camera.fx / (c - m.eye).norm();
    }
    const double half_width = m.options.search_half_width_px + 0.3 * step_px;
    const Fit fit = m.Measure(frame, pred.x(), pred.y(), half_width);
    if (m.Accept(fit)) {
      m.history.emplace_back(f, Vector2d(fit.x, fit.z));
      if (m.history.size() > 3) m.history.pop_front();
      return m.Observe(fit);
    }
    m.history.clear();
  }
  // (Re)acquire: the initial guess in the first frame, else the search along the path.
  std::optional<Vector2d> guess;
  if (f == 0 && m.options.init_uv) {
    const Vector2d nrm = UndistortPixel(m.cal.camera, *m.options.init_uv);
    const Vector3d ray = m.to_apparatus * Vector3d(nrm.x(), nrm.y(), 1.0);
    if (std::abs(ray.y()) > 1e-12) {
      const double t = -m.eye.y() / ray.y();
      if (t > 0) guess = Vector2d(m.eye.x() + t * ray.x(), m.eye.z() + t * ray.z());
    }
  }
  if (!guess) guess = m.Acquire(frame);
  if (!guess) return {};
  m.polarity = 0;
  const Fit fit = m.Measure(frame, guess->x(), guess->y(), 2 * m.options.search_half_width_px);
  if (!m.Accept(fit)) return {};
  m.history.clear();
  m.history.emplace_back(f, Vector2d(fit.x, fit.z));
  return m.Observe(fit);
}

}  // namespace uphill::bench
