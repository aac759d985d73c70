#include "outline_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "model/solver_logs.hpp"
#include "outline_ray_cost.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// The upper of the two middle values for an even count (internal::Median of track_series.hpp
// averages them), which is what the rays' inlier limit is set from.
double UpperMedian(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// A ray whose mean square (units of the noise²) is below this is an inlier.
double InlierLimit(const std::vector<double>& squares) { return kRayLossFactor * std::max(1.0, UpperMedian(squares)); }

// The lamp's inverse distance (BodyShading::LitFrom) that best explains the rays at the fit's
// start p, the centre held: one Gauss–Newton step from the prior mean over the rays that are
// inliers there, its derivative by a forward difference (each sample's shade from its basis at
// the start). *lit (the shading the rays read) is left lit by the result.
double FitLightDistance(const BodyShading& learnt, BodyShading* lit, const std::vector<RayCost*>& rays,
                        const double* p, double prior) {
  const Vector3d centre(p[kCentreX], 0, p[kCentreZ]);
  *lit = learnt.LitFrom(centre, prior);
  std::vector<std::vector<double>> at_prior(rays.size());
  std::vector<double> squares(rays.size());
  for (size_t k = 0; k < rays.size(); ++k) {
    rays[k]->ResidualsAtStart(&at_prior[k]);
    double sum = 0;
    for (double v : at_prior[k]) sum += v * v;
    squares[k] = sum / static_cast<double>(std::max<size_t>(1, at_prior[k].size()));
  }
  const double limit = InlierLimit(squares);
  std::vector<double> r0, r1;
  *lit = learnt.LitFrom(centre, prior + kLightStep);
  for (size_t k = 0; k < rays.size(); ++k)
    if (squares[k] < limit) {
      r0.insert(r0.end(), at_prior[k].begin(), at_prior[k].end());
      rays[k]->ResidualsAtStart(&r1);
    }
  const auto e0 = Eigen::Map<const Eigen::VectorXd>(r0.data(), static_cast<Eigen::Index>(r0.size()));
  const Eigen::VectorXd slope = (Eigen::Map<const Eigen::VectorXd>(r1.data(), static_cast<Eigen::Index>(r1.size())) - e0) / kLightStep;
  const double inv_prior = 1 / (kLightPrior * kLightPrior);
  double kappa = prior - slope.dot(e0) / (slope.squaredNorm() + inv_prior);
  if (!std::isfinite(kappa)) kappa = prior;
  *lit = learnt.LitFrom(centre, kappa);
  return kappa;
}

// σ_D of the smear's prior, m: the request's, or the smear held where it gives none.
double SmearPriorSigma(const FitRequest& q) { return q.smear_sigma > 0 ? q.smear_sigma : 1e-9; }

// The priors: b ~ N(0, 0.3 px), D ~ N(D_pred, σ_D).
struct PriorCost {
  Vector2d smear;
  double inv_smear_sigma;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = p[kEdgeShift] / kEdgeShiftPriorPx;
    r[1] = (p[kSmearX] - smear.x()) * inv_smear_sigma;
    r[2] = (p[kSmearZ] - smear.y()) * inv_smear_sigma;
    return true;
  }
};

// FitRequest::path: the centre's height above the path's tangent line, over σ (a vertical
// distance: across the path to within the slope's cosine).
struct PathCost {
  PathHold hold;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = (p[kCentreZ] - hold.z0 - hold.slope * (p[kCentreX] - hold.x0)) / hold.sigma;
    return true;
  }
};

// The rolling shutter's row delay (s per row) that the inlier rays prefer, every parameter free,
// and its standard error: one Gauss–Newton step in (p, δ) from the solution p at the request's
// delay, over the inlier rays' χ² and the priors. Its δ part is the least-squares delay of this
// frame to first order (the Schur complement of the smear's parameters: what the centre and the
// smear absorb of a wrong delay is given back), and the inverse's δ entry its variance (residuals
// in units of the noise). {0, 0} where the step is not defined.
std::pair<double, double> PreferredRowDelay(const std::vector<RayCost*>& costs, const std::vector<double>& squares,
                                            double limit, const double* p, const FitRequest& q) {
  DelayGramMatrix gram = DelayGramMatrix::Zero();
  for (size_t k = 0; k < costs.size(); ++k)
    if (squares[k] < limit) gram += costs[k]->DelayGram(p);
  constexpr int kDelay = kSmearParameters, kUnknowns = kSmearParameters + 1;
  using Matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;
  using Vector = Eigen::Matrix<double, kUnknowns, 1>;
  Matrix h = gram.topLeftCorner<kUnknowns, kUnknowns>();
  Vector g = gram.topRightCorner<kUnknowns, 1>();
  // The priors' rows (PriorCost): b/0.3 px and (D − D_pred)/σ_D; b held where it is.
  const double wb = 1 / (kEdgeShiftPriorPx * kEdgeShiftPriorPx);
  const double wd = 1 / std::pow(SmearPriorSigma(q), 2);
  h(kEdgeShift, kEdgeShift) += wb, g(kEdgeShift) += wb * p[kEdgeShift];
  h(kSmearX, kSmearX) += wd, g(kSmearX) += wd * (p[kSmearX] - q.smear.x());
  h(kSmearZ, kSmearZ) += wd, g(kSmearZ) += wd * (p[kSmearZ] - q.smear.y());
  if (!q.fit_edge_shift) {
    h.row(kEdgeShift).setZero(), h.col(kEdgeShift).setZero();
    h(kEdgeShift, kEdgeShift) = 1, g(kEdgeShift) = 0;
  }
  // Solved with the columns scaled to unit diagonal (metres, pixels and seconds per row).
  if (!(h.diagonal().array() > 0).all()) return {0, 0};
  const Vector d = h.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::LDLT<Matrix> ldlt(d.asDiagonal() * h * d.asDiagonal());
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return {0, 0};
  const Vector step = -(d.asDiagonal() * ldlt.solve(d.asDiagonal() * g));
  Vector unit = Vector::Zero();
  unit(kDelay) = 1;
  const double variance = d(kDelay) * d(kDelay) * ldlt.solve(unit)(kDelay);
  if (!std::isfinite(step(kDelay)) || !(variance > 0)) return {0, 0};
  return {q.row_delay + step(kDelay), std::sqrt(variance)};
}

bool InFront(const OutlineGeometry& g, double x, double z) {
  return (g.cal.pose.rotation * Vector3d(x, 0, z) + g.cal.pose.translation).z() > 2 * g.a &&
         (Vector3d(x, 0, z) - g.eye).norm() > 2 * std::max(g.a, g.a / g.s);
}

// The centre's move in the image at each successful iteration of a solve (the solver writes the
// parameters back every iteration): the last one says whether a solve stopped by its cap of
// iterations had settled.
class CentreSteps : public ceres::IterationCallback {
 public:
  CentreSteps(const OutlineGeometry& g, const double* params)
      : g_(g), params_(params), at_(g.Project(params[kCentreX], params[kCentreZ])) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0 && summary.step_is_successful) {
      const Vector2d now = g_.Project(params_[kCentreX], params_[kCentreZ]);
      last_px_ = (now - at_).norm();
      at_ = now;
    }
    return ceres::SOLVER_CONTINUE;
  }
  double last_px() const { return last_px_; }

 private:
  const OutlineGeometry& g_;
  const double* params_;
  Vector2d at_;
  double last_px_ = 0;
};

}  // namespace

std::vector<Vector3d> OutlineGeometry::OutlinePoints(double x, double z, int n) const {
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

Vector2d OutlineGeometry::Project(double x, double z) const {
  return ProjectApparatusPoint(cal.camera, cal.pose, Vector3d(x, 0, z));
}

double OutlineGeometry::PxPerRad(double x, double z) const {
  return cal.camera.fx * (Vector3d(x, 0, z) - eye_s).norm() / (Vector3d(x, 0, z) - eye).norm();
}

FitOutcome FitOutline(const OutlineGeometry& g, const FrameView& view, const BackgroundModel& background,
                      const FitRequest& q) {
  const cv::Mat& bgr = view.bgr;
  const double gain = view.gain;
  // Where samples may be read: inside the frame and the view, a pixel in for the interpolation.
  const double left = std::max(1.0, view.origin.x + 1.0), top = std::max(1.0, view.origin.y + 1.0);
  const double right = std::min(g.cal.camera.width - 2.0, view.origin.x + bgr.cols - 2.0);
  const double bottom = std::min(g.cal.camera.height - 2.0, view.origin.y + bgr.rows - 2.0);
  FitOutcome out;
  out.light_inverse_distance = q.light_inverse_distance;
  const double x = q.centre.x(), z = q.centre.y();
  if (!InFront(g, x, z)) return out;
  const int n = q.rays;
  std::vector<Vector3d> points = g.OutlinePoints(x, z, n);
  points.emplace_back(x, 0, z);
  // The smear's ends, C(∓½) = C ∓ D/2 + A/4.
  points.emplace_back(x - 0.5 * q.smear.x() + 0.25 * q.bend.x(), 0, z - 0.5 * q.smear.y() + 0.25 * q.bend.y());
  points.emplace_back(x + 0.5 * q.smear.x() + 0.25 * q.bend.x(), 0, z + 0.5 * q.smear.y() + 0.25 * q.bend.y());
  const std::vector<Vector2d> image = ProjectApparatusPoints(g.cal.camera, g.cal.pose, points);
  const Vector2d centre = image[n], smear_px = image[n + 2] - image[n + 1];
  double radius_px = 0;
  for (int k = 0; k < n; ++k) radius_px += (image[k] - centre).norm() / n;
  const int pieces = SmearPieces(smear_px.norm(), radius_px);

  SmearedBody body;
  body.a = g.a;
  body.eye = g.eye_s;
  body.px_per_rad = g.PxPerRad(x, z);
  body.sigma_px = g.sigma_px;
  // The body's shading, where it is known and the smear is long enough for it to matter.
  const bool shaded = g.shading && g.shading->ready() && smear_px.norm() > kShadedSmear * radius_px;
  BodyShading lit = shaded ? g.shading->LitFrom(Vector3d(x, 0, z), q.light_inverse_distance) : BodyShading(1.0);
  if (shaded) body.shading = &lit;
  const bool fit_light = shaded && q.fit_light;  // the lamp's distance fitted, then the centre

  // Rays: windows and their three undistorted anchors (start, middle, end).
  struct Ray {
    Vector2d origin, dir;
    double s0, s1;
    double limb;  // a point surely inside the body (if the prediction holds), px along the ray
    double shift;  // px along the ray of the predicted outline (a rolling shutter's shear), else 0
  };
  std::vector<Ray> rays;
  std::vector<Vector2d> anchors;
  const double margin_in = 1.5 + 2 * g.sigma_px, margin_out = 3.0 + 2 * g.sigma_px;
  for (int k = 0; k < n; ++k) {
    const Vector2d radial = image[k] - centre;
    const double r = radial.norm();
    if (r < 2) continue;
    Ray ray;
    ray.dir = radial / r;
    // The rolling shutter: the window follows the body's shift at the tangent point's row.
    const Vector2d offset = q.velocity * ((image[k].y() - q.reference_row) * q.row_delay);
    double shift = 0;
    if (q.row_delay != 0) shift = (g.Project(x + offset.x(), z + offset.y()) - centre).dot(ray.dir);
    const double along = 0.5 * std::abs(smear_px.dot(ray.dir));
    const double across = 0.5 * std::abs(smear_px.x() * ray.dir.y() - smear_px.y() * ray.dir.x());
    const double inward = std::min(0.85 * r, along + r - std::sqrt(std::max(0.0, r * r - across * across)));
    ray.s0 = std::max(-0.9 * r, -(inward + q.half_width_px + margin_in)) + shift;
    ray.s1 = along + q.half_width_px + margin_out + shift;
    ray.limb = -(inward + q.half_width_px + 1.5 * g.sigma_px + 0.3) + shift;
    ray.origin = image[k];
    ray.shift = shift;
    // Inside the picture (with a pixel for the interpolation) and clear of the occluder.
    bool usable = true;
    for (double s : {ray.s0, 0.5 * (ray.s0 + ray.s1), ray.s1}) {
      const Vector2d p = ray.origin + s * ray.dir;
      usable = usable && p.x() >= left && p.y() >= top && p.x() < right && p.y() < bottom;
    }
    if (!usable) continue;
    rays.push_back(ray);
    for (double s : {ray.s0, 0.5 * (ray.s0 + ray.s1), ray.s1}) anchors.push_back(ray.origin + s * ray.dir);
  }
  out.rays_tried = static_cast<int>(rays.size());
  if (rays.size() < 8) return out;
  const std::vector<Vector2d> normalised = UndistortPixels(g.cal.camera, anchors);

  double params[kSmearParameters] = {x, z, q.smear.x(), q.smear.y(), 0.0};
  ceres::Problem problem;
  std::vector<RayCost*> costs;
  std::vector<ceres::ResidualBlockId> ray_blocks;
  int without_background = 0;
  const double inv_noise = 1.0 / std::max(q.noise, 1e-4);
  const cv::Mat& occluder = *g.occluder;
  for (size_t k = 0; k < rays.size(); ++k) {
    const Ray& ray = rays[k];
    RaySamples samples;
    const bool rolling = q.row_delay > 0 || q.estimate_row_delay;
    samples.velocity = q.velocity;
    samples.row_delay = q.row_delay;
    samples.bend = q.bend;
    samples.pieces = pieces;
    const double length = ray.s1 - ray.s0;
    const double step = std::clamp(length / 40, kLeastStep, 3.0);
    const int count = static_cast<int>(std::ceil(length / step)) + 1;
    const Vector2d& na = normalised[3 * k];
    const Vector2d& nm = normalised[3 * k + 1];
    const Vector2d& nb = normalised[3 * k + 2];
    bool hidden = false, known = true;
    for (int i = 0; i < count && !hidden; ++i) {
      const double t = static_cast<double>(i) / (count - 1);
      const Vector2d p = ray.origin + (ray.s0 + t * length) * ray.dir;
      hidden = occluder.at<std::uint8_t>(static_cast<int>(p.y() + 0.5), static_cast<int>(p.x() + 0.5)) != 0;
      // Quadratic through the three undistorted anchors (the lens bends a 40 px segment by far
      // less than its curvature can show).
      const Vector2d m = na * ((1 - t) * (1 - 2 * t)) + nm * (4 * t * (1 - t)) + nb * (t * (2 * t - 1));
      Vector3d d = g.to_apparatus * Vector3d(m.x(), m.y(), 1.0);
      d.y() *= g.s;
      samples.dirs.push_back(d.normalized());
      samples.along.push_back(2 * t - 1);
      if (!shaded && q.limb_profile) {
        const double depth = std::max(0.0, ray.shift - (ray.s0 + t * length));  // px inside the outline
        samples.limb_depth.push_back(std::min(1.0, std::sqrt(2 * depth / radius_px)));
      }
      if (rolling) samples.rows.push_back(p.y() - q.reference_row);
      samples.image.push_back(SampleLinear(bgr, background.table(), p.x() - view.origin.x, p.y() - view.origin.y));
      if (known && background.Known(p.x(), p.y())) samples.back.push_back(background.At(p.x(), p.y()) * gain);
      else known = false;
    }
    if (hidden) {
      --out.rays_tried;  // hidden by a rail: not part of the visible outline
      continue;
    }
    if (!known) samples.back.clear(), ++without_background;
    // Inner edges are not outline edges: where the body's colour changes inside the limb (a
    // painted band, a dot, a seam), the window ends, so that the limb's colour is one colour.
    const int limb = static_cast<int>(std::lround((ray.limb - ray.s0) / step));
    if (step <= kLeastStep && limb >= 1 && limb + 1 < count) {
      const cv::Vec3f colour = 0.5f * (samples.image[limb] + samples.image[limb + 1]);
      const double threshold = std::max(0.25 * cv::norm(colour - samples.image.back()), 5 * q.noise);
      for (int j = limb - 1; j >= 0; --j)
        if (cv::norm(samples.image[j] - colour) > threshold) {
          const auto cut = [j](auto& v) {
            if (!v.empty()) v.erase(v.begin(), v.begin() + j + 1);
          };
          cut(samples.dirs), cut(samples.along), cut(samples.image), cut(samples.back), cut(samples.rows);
          cut(samples.limb_depth);
          break;
        }
    }
    // A smear's edge along this ray is a ramp as long as the smear's extent along it: the fit
    // reads it at kRampSamples samples (at most 3 px apart), not at the window's finer step, which
    // the band's edges above and the sharp edges across the motion need.
    const double fit_step = std::min(3.0, std::abs(smear_px.dot(ray.dir)) / kRampSamples);
    if (fit_step > step) ThinOut(&samples, static_cast<int>(std::ceil(length / fit_step)) + 1);
    const double loss_scale = std::sqrt(kRayLossFactor * 3.0 * samples.dirs.size());
    auto* cost = new RayCost(body, std::move(samples), inv_noise, shaded, params);
    if (q.estimate_row_delay) cost->KeepGradients();
    costs.push_back(cost);
    ray_blocks.push_back(problem.AddResidualBlock(cost, new ceres::CauchyLoss(loss_scale), params));
  }
  out.rays_fitted = static_cast<int>(costs.size());
  out.rays_without_background = without_background;
  if (costs.size() < 8) return out;
  const double sigma_d = SmearPriorSigma(q);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 3, kSmearParameters>(
                               new PriorCost{q.smear, 1.0 / sigma_d}),
                           nullptr, params);
  if (q.path)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PathCost, 1, kSmearParameters>(new PathCost{*q.path}),
                             nullptr, params);
  if (!q.fit_edge_shift) problem.SetManifold(params, new ceres::SubsetManifold(kSmearParameters, {kEdgeShift}));
  QuietSolverLogs();
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  // The request's cap (FitRequest::iterations). Each iteration costs a Jacobian of every sample.
  solver.max_num_iterations = std::max(1, q.iterations);
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  // Parameters are metres near 0.5 and pixels: 1e-7 of the centre is below 1e-4 px; the cost's
  // relative change 1e-7 is far below what the noise moves it.
  solver.function_tolerance = 1e-7;
  solver.parameter_tolerance = 1e-7;
  ceres::Solver::Summary summary;
  CentreSteps steps(g, params);
  solver.callbacks.push_back(&steps);
  solver.update_state_every_iteration = true;  // for CentreSteps
  // The shading learnt where the body rested, lit from where this frame sees the lamp at the
  // fit's start (a first pass's result, or the prediction where the model measured the frame
  // before): one solve from there; solving first and then once more from the result
  // would cost a second solve for no better centre.
  if (fit_light) {
    out.light_inverse_distance = FitLightDistance(*g.shading, &lit, costs, params, q.light_inverse_distance);
    for (RayCost* cost : costs) cost->Shade();
  }
  ceres::Solve(solver, &problem, &summary);
  for (double v : params)
    if (!std::isfinite(v)) return out;
  if (!InFront(g, params[kCentreX], params[kCentreZ])) return out;

  std::vector<double> squares(costs.size()), contrasts(costs.size());
  for (size_t k = 0; k < costs.size(); ++k) costs[k]->Assess(params, &contrasts[k], &squares[k]);
  const double median = UpperMedian(squares);
  const double limit = InlierLimit(squares);
  double sum = 0;
  std::vector<double> inlier_contrasts;
  for (size_t k = 0; k < costs.size(); ++k)
    if (squares[k] < limit) {
      ++out.inliers;
      sum += squares[k];
      inlier_contrasts.push_back(contrasts[k]);
    }
  if (out.inliers == 0) return out;
  std::nth_element(inlier_contrasts.begin(), inlier_contrasts.begin() + inlier_contrasts.size() / 2,
                   inlier_contrasts.end());
  out.contrast = inlier_contrasts[inlier_contrasts.size() / 2];
  out.misfit = std::sqrt(sum / out.inliers);
  out.noise = q.noise * std::sqrt(median);
  std::copy(std::begin(params), std::end(params), out.p.begin());
  out.last_step_px = steps.last_px();
  ceres::Problem::EvaluateOptions rays_only;
  rays_only.residual_blocks = ray_blocks;
  problem.Evaluate(rays_only, &out.ray_cost, nullptr, nullptr, nullptr);
  if (q.estimate_row_delay) {
    const auto [delay, sigma] = PreferredRowDelay(costs, squares, limit, params, q);
    out.row_delay = delay, out.row_delay_sigma = sigma;
  }
  out.ok = true;
  return out;
}

}  // namespace uphill::internal
