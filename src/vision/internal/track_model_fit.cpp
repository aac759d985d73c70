#include "track_model_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "model/input_error.hpp"
#include "model/solver_logs.hpp"
#include "motion/motion.hpp"
#include "track_fit_errors.hpp"

namespace uphill::internal {
namespace {

// Motions by parameters. One Jacobian by central differences needs the motion at (x0, p) and at
// x0 ± h and p ± h (t0 only shifts time): five motions shared by every residual block.
class ModelCache {
 public:
  ModelCache(const Scene& scene, const TrackAnalysisOptions& o) : scene_(scene), o_(o) {}

  // x(t) of the motion released from rest at x0 at time t0; p = g_eff or μ.
  double Predict(double t, double x0, double t0, double p) const {
    const Entry& e = Get(x0, p);
    const double tau = (t - t0) * TimeScale(p);
    if (tau <= 0.0 || e.motion->direction() == 0) return x0;
    if (tau >= e.motion->end_time()) return e.end_x;
    return e.motion->At(tau).x;
  }
  const Motion& Get(double x0, double p, double* time_scale) const {
    *time_scale = TimeScale(p);
    return *Get(x0, p).motion;
  }

 private:
  struct Entry {
    double x0, p;
    std::shared_ptr<Motion> motion;
    double end_x;
  };
  bool fit_g() const { return o_.fit == TrackFitParameter::kEffectiveG; }
  // Without friction g only scales time: x(t; g) = x(t·sqrt(g/g_ref); g_ref).
  double TimeScale(double p) const { return fit_g() ? std::sqrt(p / o_.g) : 1.0; }
  const Entry& Get(double x0, double p) const {
    const double key_p = fit_g() ? 0.0 : std::max(p, 0.0);
    for (std::size_t i = 0; i < entries_.size(); ++i)
      if (entries_[i].x0 == x0 && entries_[i].p == key_p) {
        std::rotate(entries_.begin(), entries_.begin() + i, entries_.begin() + i + 1);
        return entries_.front();
      }
    MotionOptions mo;
    mo.g = o_.g;
    if (fit_g()) {
      mo.method = MotionMethod::kQuadrature;
      mo.tolerance = 1e-12;
    } else {
      mo.method = MotionMethod::kOde;
      mo.mu = key_p;
      mo.tolerance = 1e-10;
    }
    auto motion = std::make_shared<Motion>(scene_, x0, mo);
    const double end = motion->end_time();
    const double end_x = std::isfinite(end) ? motion->At(end).x : x0;
    entries_.insert(entries_.begin(), Entry{x0, key_p, std::move(motion), end_x});
    if (entries_.size() > 8) entries_.pop_back();
    return entries_.front();
  }

  const Scene& scene_;
  TrackAnalysisOptions o_;
  mutable std::vector<Entry> entries_;  // most recently used first
};

// The parameter block: (x0, t0 − t_ref, p), t0 as an offset so that the difference step is
// relative to a small number, not to a clock that may read 3600 s.
struct FrameResidual {
  std::shared_ptr<const ModelCache> model;
  double t, x, inv_sigma, t_ref;
  // The motion must leave x0 in the measured direction: μ holding the ball at x0 is refused.
  int direction;
  bool operator()(const double* q, double* r) const {
    try {
      double scale = 1.0;
      if (model->Get(q[0], q[2], &scale).direction() != direction) return false;
      r[0] = (model->Predict(t, q[0], t_ref + q[1], q[2]) - x) * inv_sigma;
      return std::isfinite(r[0]);
    } catch (const InputError&) {
      return false;
    }
  }
};

// Events of the motion at q, absolute times.
std::vector<MotionEvent> ModelEvents(const ModelCache& model, const Eigen::Vector3d& q, double t_ref) {
  double scale = 1.0;
  const Motion& m = model.Get(q(0), q(2), &scale);
  std::vector<MotionEvent> events = m.events();
  for (auto& e : events) e.t = t_ref + q(1) + e.t / scale;
  return events;
}

// The track's own scale, m per raw pixel: the median of |Δ(x, z)| / |Δ(u, v)| between each frame
// of the window and the first later one at least 5 px away (far above the tracker's error, near
// enough that perspective changes the scale little). A centre that never moves 5 px (a far camera
// looking along the rails: 1.5 mm per pixel, a fit over 7 mm) takes the widest step from the
// first frame, if it reaches 1 px (the tracker's 0.1 px then costs at most 10 % of the scale);
// 0 when the centre moved less.
double MetresPerPixel(const Series& s, const std::vector<int>& use) {
  std::vector<double> ratios;
  for (std::size_t k = 0; k < use.size(); ++k)
    for (std::size_t l = k + 1; l < use.size(); ++l) {
      const int i = use[k], j = use[l];
      const double px = std::hypot(s.u[j] - s.u[i], s.v[j] - s.v[i]);
      if (!(px >= 5.0)) continue;
      ratios.push_back(std::hypot(s.x[j] - s.x[i], s.z[j] - s.z[i]) / px);
      break;
    }
  if (!ratios.empty()) return Median(ratios);
  double widest = 0, scale = 0;
  for (int j : use) {
    const int i = use.front();
    const double px = std::hypot(s.u[j] - s.u[i], s.v[j] - s.v[i]);
    if (px >= 1.0 && px > widest) widest = px, scale = std::hypot(s.x[j] - s.x[i], s.z[j] - s.z[i]) / px;
  }
  return scale;
}

// The statistical and systematic parts of each parameter's uncertainty (track_fit_errors.hpp).
std::optional<FitErrors> AddErrorParts(const Series& s, const std::vector<int>& use, const TrackAnalysisOptions& o,
                                      ceres::Problem& problem, TrackFit* fit) {
  ceres::Problem::EvaluateOptions plain;
  plain.apply_loss_function = false;
  std::vector<double> scaled;  // residuals / u_x
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(plain, nullptr, &scaled, nullptr, &crs)) return std::nullopt;
  const int n = static_cast<int>(use.size());
  FitErrorInputs in;
  in.derivatives = Eigen::MatrixXd::Zero(n, 3);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) in.derivatives(r, crs.cols[k]) = crs.values[k] * o.u_x;
  in.weights.resize(n);
  in.residuals.resize(n);
  in.x.resize(n);
  in.systematic.resize(n);
  if (!s.time_u.empty()) in.time_systematic.resize(n);
  for (int i = 0; i < n; ++i) {
    if (!s.time_u.empty()) in.time_systematic(i) = s.time_u[use[i]];
    in.residuals(i) = scaled[i] * o.u_x;
    in.weights(i) = std::abs(scaled[i]) <= o.huber_sigmas ? 1.0 : o.huber_sigmas / std::abs(scaled[i]);
    in.x(i) = s.x[use[i]];
  }
  // The motion blur grows with the image speed: pixels per frame interval, from the neighbours.
  std::vector<double> t, u, v;
  for (int i : use) t.push_back(s.t[i]), u.push_back(s.u[i]), v.push_back(s.v[i]);
  const std::vector<double> speed = PixelsPerFrame(t, u, v);
  fit->metres_per_pixel = MetresPerPixel(s, use);
  for (int i = 0; i < n; ++i) {
    in.systematic(i) =
        o.fit_systematic_scale * fit->metres_per_pixel * (o.tracker_floor_px + o.tracker_blur * speed[i]);
    fit->systematic.push_back(in.systematic(i));
  }
  if (fit->metres_per_pixel == 0.0)
    fit->notes.push_back("the track's pixel coordinates do not move: the tracker's systematic error is not estimated");
  if (in.time_systematic.size() > 0 && in.time_systematic.maxCoeff() > 0)
    fit->notes.push_back("the times carry the uncertainty of the rolling shutter's measured readout (up to " +
                         Printf("%.2g", in.time_systematic.maxCoeff() * 1e3) +
                         " ms in this window, shared by every frame): it is in the systematic part");
  const FitErrors errors = EstimateFitErrors(in);
  fit->residual_lag1 = errors.lag1;
  for (int j = 0; j < 3; ++j) {
    FittedParameter& p = fit->parameters[j];
    p.se_statistical = std::sqrt(errors.residual_covariance(j, j));
    p.se_systematic = std::sqrt(errors.systematic_covariance(j, j));
    p.u = std::hypot(*p.se_statistical, *p.se_systematic);
  }
  return errors;
}

}  // namespace

void FitModel(const Series& s, int begin, int end, int direction, const Scene& scene, const TrackAnalysisOptions& o,
              double x0_start, double band, TrackFit* fit) {
  const bool fit_g = o.fit == TrackFitParameter::kEffectiveG;
  fit->fitted = fit_g ? "g" : "mu";
  std::vector<int> use;
  int off_rails = 0;
  for (int i = begin; i < end; ++i) {
    if (s.x[i] < scene.x_low() - band || s.x[i] > scene.x_max() + band) {
      ++off_rails;
      continue;
    }
    use.push_back(i);
  }
  if (off_rails > 0)
    fit->notes.push_back(std::to_string(off_rails) + " frames lie beyond the rails' range [x_low, x_max] by more than " +
                         Mm(band) + ": left out of the fit");
  if (use.size() < 6) {
    fit->unavailable = "too few frames in the fit window (" + std::to_string(use.size()) + ", need 6)";
    return;
  }
  if (!fit_g && scene.rod_radius() > 0 && scene.body().kind == BodyKind::kSpheroid) {
    fit->unavailable = "fitting mu needs the ode method, which a spheroid on rods does not have; use --fit g";
    return;
  }
  // Bounds of x0: the measured direction's side of X, away from X by more than a difference step.
  const double margin = 1e-4 * std::max(std::abs(scene.x_max()), std::abs(scene.x_low()));
  double lo = scene.x_low() + margin, hi = scene.x_max() - margin;
  if (const auto x_eq = scene.x_eq()) (direction > 0 ? lo : hi) = *x_eq + (direction > 0 ? margin : -margin);
  if (!(lo < hi)) {
    fit->unavailable = "the scene leaves no room for a release " + std::string(direction > 0 ? "beyond" : "below") + " X";
    return;
  }
  if (!scene.x_eq() && (x0_start < lo - band || x0_start > hi + band)) {
    fit->unavailable = "the ball starts at " + Mm(x0_start) + ", outside the path [x_low, x_max] = [" +
                       Mm(scene.x_low()) + ", " + Mm(scene.x_max()) + "]: check the scene flags and the calibration";
    return;
  }
  if (x0_start < lo - band || x0_start > hi + band) {
    // Released at rest, the body moves away from X; moving toward it, it was pushed.
    fit->unavailable = "the ball starts at " + Mm(x0_start) + " and moves " + (direction > 0 ? "up" : "down") +
                       ", toward X = " + Mm(scene.x_eq().value_or(0)) +
                       ": it was pushed (released from rest it would roll away from X), which the model of a "
                       "release from rest does not describe";
    return;
  }
  if (x0_start < lo || x0_start > hi)
    fit->notes.push_back("the measured release position " + Mm(x0_start) + " lies within " + Mm(band) + " beyond " +
                         (scene.x_eq() ? "X = " + Mm(*scene.x_eq()) + " for the measured direction"
                                       : "the path [x_low, x_max]") +
                         ": the scene or the calibration is off; the fit starts at the nearest allowed position");
  auto model = std::make_shared<ModelCache>(scene, o);
  Eigen::Vector3d q;
  q(0) = std::clamp(x0_start, lo, hi);
  q(2) = fit_g ? o.g : 0.0;
  if (!fit_g) {
    // Start μ at a tenth of the slope at the release: it must be below |z'(x0)| to let it move.
    q(2) = 0.1 * std::abs(scene.At(q(0)).dzdx);
  }
  // Start t0 from the first frame that left the band: t0 = t_out − (time the model takes to get there).
  const double t_ref = s.t[use.front()];
  q(1) = 0.0;
  try {
    double scale = 1.0;
    const Motion& m = model->Get(q(0), q(2), &scale);
    if (m.direction() != direction) {
      fit->unavailable = "the model released at " + Mm(q(0)) + " does not move " + (direction > 0 ? "up" : "down");
      return;
    }
    for (int i : use)
      if (std::abs(s.x[i] - q(0)) > band) {
        const double time = m.TimeAt(s.x[i]);
        q(1) = s.t[i] - t_ref - (std::isfinite(time) ? time / scale : 0.0);
        break;
      }
  } catch (const InputError& e) {
    fit->unavailable = std::string("the model cannot start: ") + e.what();
    return;
  }

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::HuberLoss loss(o.huber_sigmas);
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = 1e-5;
  for (int i : use) {
    auto* cost = new ceres::NumericDiffCostFunction<FrameResidual, ceres::CENTRAL, 1, 3>(
        new FrameResidual{model, s.t[i], s.x[i], 1.0 / o.u_x, t_ref, direction}, ceres::TAKE_OWNERSHIP, 1, diff);
    problem.AddResidualBlock(cost, &loss, q.data());
  }
  problem.SetParameterLowerBound(q.data(), 0, lo);
  problem.SetParameterUpperBound(q.data(), 0, hi);
  problem.SetParameterLowerBound(q.data(), 2, fit_g ? 1e-6 * o.g : 0.0);
  QuietSolverLogs();
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 100;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-16;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  fit->iterations = static_cast<int>(summary.iterations.size());
  fit->termination = summary.message;
  if (!summary.IsSolutionUsable()) {
    fit->unavailable = "Ceres found no usable solution: " + summary.message;
    return;
  }

  const double t0 = t_ref + q(1);
  double chi2 = 0;
  for (int i : use) {
    const double predicted = model->Predict(s.t[i], q(0), t0, q(2));
    fit->t.push_back(s.t[i]);
    fit->measured.push_back(s.x[i]);
    fit->predicted.push_back(predicted);
    fit->rows.push_back(s.rows[i]);
    chi2 += (predicted - s.x[i]) * (predicted - s.x[i]);
  }
  const int n = static_cast<int>(use.size());
  fit->rms_residual = std::sqrt(chi2 / n);
  fit->chi2 = chi2 / (o.u_x * o.u_x);
  fit->dof = n - 3;
  fit->reduced_chi2 = fit->chi2 / fit->dof;
  fit->available = true;

  // Ceres logs an error for a rank-deficient Jacobian; a track that cannot determine the three
  // parameters is an expected outcome here, so look first (same criterion: the reciprocal
  // condition number of JᵀJ, slightly stricter than Ceres' 1e-14 so Ceres never meets it).
  ceres::CRSMatrix crs;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) jacobian(r, crs.cols[k]) = crs.values[k];
  const Eigen::VectorXd singular = Eigen::JacobiSVD<Eigen::MatrixXd>(jacobian).singularValues();
  const bool full_rank = singular.size() == 3 && singular(0) > 0 &&
                         std::pow(singular(2) / singular(0), 2) > 1e-13;
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.num_threads = 1;
  ceres::Covariance covariance(co);
  const std::vector<std::pair<const double*, const double*>> blocks = {{q.data(), q.data()}};
  if (full_rank && covariance.Compute(blocks, &problem)) {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c;
    if (covariance.GetCovarianceBlock(q.data(), q.data(), c.data())) fit->covariance = Eigen::Matrix3d(c);
  }
  if (!fit->covariance)
    fit->notes.push_back("the frames do not determine x0, t0 and " + fit->fitted +
                         " together (singular covariance): no standard errors");
  const double scale = std::sqrt(std::max(fit->reduced_chi2, 0.0));
  const char* names[] = {"x0", "t0", fit_g ? "g" : "mu"};
  const char* units[] = {"m", "s", fit_g ? "m/s2" : ""};
  const double values[] = {q(0), t0, q(2)};
  for (int j = 0; j < 3; ++j) {
    FittedParameter p;
    p.name = names[j];
    p.unit = units[j];
    p.value = values[j];
    if (fit->covariance) {
      p.se = std::sqrt((*fit->covariance)(j, j));
      p.se_scaled = *p.se * scale;
    }
    fit->parameters.push_back(p);
  }
  std::optional<FitErrors> errors;
  if (fit->covariance) errors = AddErrorParts(s, use, o, problem, fit);
  if (q(0) <= lo + 1e-9 * std::abs(lo) || q(0) >= hi - 1e-9 * std::abs(hi))
    fit->notes.push_back("x0 ended at its bound (" + Mm(q(0)) + "): the data want a release where the model cannot " +
                         "start this motion (" + (scene.x_eq() ? "the other side of X" : "outside the path") + ")");
  if (!fit_g && q(2) <= 0.0)
    fit->notes.push_back("mu ended at its bound 0: read the result as mu <= its standard error");
  if (fit->reduced_chi2 > 4.0)
    fit->notes.push_back("reduced chi-square " + Printf("%.3g", fit->reduced_chi2) +
                         ": the residuals are larger than the stated u_x; the scaled standard errors are the honest ones, "
                         "or the model misses something (see the residual figure)");

  // Events of the fitted motion, with uncertainties propagated by central differences through
  // the covariance (inflated by χ²/ν when that exceeds 1) or the statistical + systematic parts
  // (the larger); none when a step changes the events.
  const std::vector<MotionEvent> events = ModelEvents(*model, q, t_ref);
  Eigen::MatrixXd dt = Eigen::MatrixXd::Zero(events.size(), 3), dx = dt;
  bool propagate = fit->covariance.has_value();
  for (int j = 0; j < 3 && propagate; ++j) {
    const double h = std::max(1e-5 * std::abs(q(j)), 1e-8);
    Eigen::Vector3d plus = q, minus = q;
    plus(j) += h;
    minus(j) -= h;
    if (j == 2 && minus(2) < 0) minus(2) = 0;
    try {
      const auto ep = ModelEvents(*model, plus, t_ref), em = ModelEvents(*model, minus, t_ref);
      if (ep.size() != events.size() || em.size() != events.size()) propagate = false;
      for (std::size_t k = 0; k < events.size() && propagate; ++k) {
        if (ep[k].kind != events[k].kind || em[k].kind != events[k].kind) propagate = false;
        dt(k, j) = (ep[k].t - em[k].t) / (plus(j) - minus(j));
        dx(k, j) = (ep[k].x - em[k].x) / (plus(j) - minus(j));
      }
    } catch (const InputError&) {
      propagate = false;
    }
  }
  const Eigen::Matrix3d c_events = propagate ? Eigen::Matrix3d(*fit->covariance * std::max(1.0, fit->reduced_chi2))
                                             : Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < events.size(); ++k) {
    TrackEvent e;
    e.kind = EventName(events[k].kind);
    e.t.value = events[k].t;
    e.x.value = events[k].x;
    if (propagate && std::isfinite(events[k].t)) {
      const Eigen::Vector3d gt = dt.row(k).transpose(), gx = dx.row(k).transpose();
      // The larger of the stated σ's (inflated by χ²/ν) and the statistical + systematic parts'.
      const auto larger = [&](const Eigen::Vector3d& g) {
        return std::sqrt(std::max(g.dot(c_events * g), errors ? g.dot(errors->Covariance() * g) : 0.0));
      };
      e.t.u = larger(gt);
      e.x.u = larger(gx);
      if (*e.x.u == 0.0) e.x.u.reset();  // x_max, x_low: fixed by the scene
    }
    e.method = "fitted model";
    fit->model_events.push_back(e);
  }
  // The fitted curve, dense, over the window.
  const double t_first = s.t[use.front()], t_last = s.t[use.back()];
  for (int k = 0; k <= 400; ++k) {
    const double t = t_first + (t_last - t_first) * k / 400.0;
    fit->curve.emplace_back(t, model->Predict(t, q(0), t0, q(2)));
  }
}

}  // namespace uphill::internal
