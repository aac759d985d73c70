#include "vision/track_analysis.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "motion/motion.hpp"

namespace uphill {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Mm(double metres) { return Printf("%.4g", metres * 1e3) + " mm"; }

double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  const double upper = v[mid];
  if (v.size() % 2) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + mid));
}

// Mean and sample standard deviation of v[begin, end).
std::pair<double, double> MeanAndSd(const std::vector<double>& v, int begin, int end) {
  const int n = end - begin;
  const double mean = std::accumulate(v.begin() + begin, v.begin() + end, 0.0) / n;
  double ss = 0;
  for (int i = begin; i < end; ++i) ss += (v[i] - mean) * (v[i] - mean);
  return {mean, n > 1 ? std::sqrt(ss / (n - 1)) : 0.0};
}

// The frames found, in time order.
struct Series {
  std::vector<double> t, x, z;
  std::vector<int> rows;
  int size() const { return static_cast<int>(t.size()); }
};

// Walking from the first frame (backward: from the last), the number of frames before the first
// one that leaves the band |x − m| ≤ band, m the median of at most `reference` frames before it,
// confirmed by `confirm` consecutive frames out on the same side; nullopt if none leaves.
std::optional<int> FirstDeparture(const std::vector<double>& v, bool backward, double band, int confirm,
                                  int reference) {
  const int n = static_cast<int>(v.size());
  const auto at = [&](int j) { return v[backward ? n - 1 - j : j]; };
  std::vector<double> window;
  double m = at(0);
  for (int j = 1; j < n; ++j) {
    if (j <= reference) {
      window.clear();
      for (int k = 0; k < j; ++k) window.push_back(at(k));
      m = Median(window);
    }
    const double side = at(j) - m;
    if (std::abs(side) <= band || j + confirm > n) continue;
    bool confirmed = true;
    for (int c = 1; c < confirm && confirmed; ++c) {
      const double d = at(j + c) - m;
      confirmed = std::abs(d) > band && (d > 0) == (side > 0);
    }
    if (confirmed) return j;
  }
  return std::nullopt;
}

// The vertex of a least-squares parabola x = c0 + c1·τ + c2·τ², τ = t − t[centre], through the
// frames around `centre` whose smoothed x is within `reach` of the centre's (at least two on
// each side); frames more than 4σ off the first parabola (glitches) are dropped and it is fitted
// again. Time and position with standard errors from the stated σ. nullopt when the parabola
// does not turn the right way (sign = +1 a maximum) or its vertex lies outside the frames used.
std::optional<TrackEvent> ParabolaVertex(const Series& s, const std::vector<double>& smooth, int centre, double reach,
                                         int sign, double sigma, int lo_limit, int hi_limit) {
  int lo = centre, hi = centre;
  const auto near = [&](int i) { return std::abs(smooth[i] - smooth[centre]) <= reach; };
  while (lo - 1 >= lo_limit && centre - lo < 40 && (near(lo - 1) || centre - lo < 2)) --lo;
  while (hi + 1 <= hi_limit && hi - centre < 40 && (near(hi + 1) || hi - centre < 2)) ++hi;
  int n = hi - lo + 1;
  if (n < 5 || centre - lo < 2 || hi - centre < 2) return std::nullopt;
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (int i = lo; i <= hi; ++i) {
    const double tau = s.t[i] - s.t[centre];
    a.row(i - lo) << 1.0, tau, tau * tau;
    b(i - lo) = s.x[i];
  }
  Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd residual = a * c - b;
  for (int k = 0; k < residual.size(); ++k)
    if (std::abs(residual(k)) > 4 * sigma) {  // a zero row does not count
      a.row(k).setZero();
      b(k) = 0;
      --n;
    }
  if (n < 5) return std::nullopt;
  c = a.colPivHouseholderQr().solve(b);
  if (!(c(2) * sign < 0)) return std::nullopt;
  const Eigen::Matrix3d cov = sigma * sigma * (a.transpose() * a).inverse();
  const double tau = -c(1) / (2 * c(2));
  if (!(tau >= s.t[lo] - s.t[centre] && tau <= s.t[hi] - s.t[centre])) return std::nullopt;
  const Eigen::Vector3d dtau(0.0, -1.0 / (2 * c(2)), c(1) / (2 * c(2) * c(2)));
  const Eigen::Vector3d dx(1.0, -c(1) / (2 * c(2)), c(1) * c(1) / (4 * c(2) * c(2)));
  TrackEvent e;
  e.kind = "turning point";
  e.t = {s.t[centre] + tau, std::sqrt(dtau.dot(cov * dtau))};
  e.x = {c(0) - c(1) * c(1) / (4 * c(2)), std::sqrt(dx.dot(cov * dx))};
  e.method = "vertex of a parabola through " + std::to_string(n) + " frames";
  return e;
}

// The final rest from the frames [begin, end): x = x_r for t ≥ t_r and x = x_r + c·(t_r − t)²
// before (the body stops with a finite deceleration, so it creeps into its rest position, and a
// plain mean of the frames near it is biased toward where it came from). Least squares in
// (x_r, c) for each candidate t_r among the frame times, the t_r of the smallest residual sum
// kept; u(x_r) from the residual scatter and the design at that t_r.
struct RestFit {
  Estimate x;
  double t = 0, scatter = 0;
  int frames = 0;
};
std::optional<RestFit> FitRest(const Series& s, int begin, int end, int min_frames) {
  const int n = end - begin;
  if (n < 4) return std::nullopt;
  std::optional<RestFit> best;
  double best_rss = kInf;
  // The approach lies at the start of the tail: 200 candidates keep an hour of rest cheap.
  const int last = std::min(end - std::max(min_frames / 2, 2), begin + 200);
  for (int r = begin; r <= last; ++r) {
    Eigen::MatrixXd a(n, 2);
    Eigen::VectorXd b(n);
    for (int i = begin; i < end; ++i) {
      const double before = std::max(s.t[r] - s.t[i], 0.0);
      a.row(i - begin) << 1.0, before * before;
      b(i - begin) = s.x[i];
    }
    if (r == begin) a.col(1).setZero();  // no approach: the plain mean
    const auto qr = a.colPivHouseholderQr();
    const Eigen::Vector2d c = qr.solve(b);
    const double rss = (a * c - b).squaredNorm();
    if (!(rss < best_rss)) continue;
    best_rss = rss;
    const double scatter = std::sqrt(rss / std::max(n - 3, 1));
    Eigen::Matrix2d ata = a.transpose() * a;
    const double var = r == begin ? 1.0 / n : ata.inverse()(0, 0);
    best = RestFit{{c(0), scatter * std::sqrt(var)}, s.t[r], scatter, end - r};
  }
  return best;
}

// ---- The model and its fit -------------------------------------------------------------------

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
    FittedParameter p{names[j], units[j], values[j], std::nullopt, std::nullopt};
    if (fit->covariance) {
      p.se = std::sqrt((*fit->covariance)(j, j));
      p.se_scaled = *p.se * scale;
    }
    fit->parameters.push_back(p);
  }
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
  // the covariance (inflated by χ²/ν when that exceeds 1); none when a step changes the events.
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
      e.t.u = std::sqrt(gt.dot(c_events * gt));
      e.x.u = std::sqrt(gx.dot(c_events * gx));
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

void RequireOptions(const TrackAnalysisOptions& o) {
  if (!(o.u_x > 0.0 && std::isfinite(o.u_x))) throw InputError("u_x", "must be > 0 (the stated position uncertainty)");
  if (!(o.g > 0.0 && std::isfinite(o.g))) throw InputError("g", "must be > 0");
  if (!(o.band_sigmas > 0.0 && std::isfinite(o.band_sigmas))) throw InputError("band_sigmas", "must be > 0");
  if (!(o.huber_sigmas > 0.0 && std::isfinite(o.huber_sigmas))) throw InputError("huber_sigmas", "must be > 0");
  if (o.confirm_frames < 1) throw InputError("confirm_frames", "must be >= 1");
  if (o.reference_frames < 1) throw InputError("reference_frames", "must be >= 1");
  if (o.rest_frames < 2) throw InputError("rest_frames", "must be >= 2");
}

}  // namespace

const FittedParameter* TrackFit::Parameter(const std::string& name) const {
  for (const auto& p : parameters)
    if (p.name == name) return &p;
  return nullptr;
}

TrackAnalysis AnalyseTrack(const Track& track, const Scene& scene, const TrackAnalysisOptions& o) {
  RequireOptions(o);
  TrackAnalysis a;
  a.source = track.source;
  a.options = o;
  a.frames = static_cast<int>(track.frames.size());
  if (track.frames.empty()) throw InputError(track.source, "the track has no frames");
  Series s;
  for (std::size_t i = 0; i < track.frames.size(); ++i) {
    // ReadTrack checks these; a Track built in memory (uphill track --analyse) is checked here.
    const TrackFrame& f = track.frames[i];
    const std::string where = track.source + ", row " + std::to_string(f.row);
    if (!std::isfinite(f.t) || (i > 0 && !(f.t > track.frames[i - 1].t)))
      throw InputError(where, "times must be finite and increase");
    if (f.found && !(std::isfinite(f.x) && std::isfinite(f.z)))
      throw InputError(where, "a frame with the ball needs finite x and z");
  }
  for (const TrackFrame& f : track.frames)
    if (f.found) {
      s.t.push_back(f.t);
      s.x.push_back(f.x);
      s.z.push_back(f.z);
      s.rows.push_back(f.row);
      a.measured.emplace_back(f.t, f.x);
    }
  a.found = s.size();
  if (a.found == 0)
    throw InputError(track.source, "the ball was not found in any of the " + std::to_string(a.frames) +
                                       " frames (every row has quality 0): nothing to analyse");
  if (a.found < 2)
    throw InputError(track.source, "the ball was found in only 1 of " + std::to_string(a.frames) +
                                       " frames: a track needs at least 2");
  if (a.frames > 1) {
    std::vector<double> steps;
    for (std::size_t i = 1; i < track.frames.size(); ++i) steps.push_back(track.frames[i].t - track.frames[i - 1].t);
    a.frame_interval = Median(steps);
  }
  if (a.found < a.frames)
    a.notes.push_back(std::to_string(a.frames - a.found) + " of " + std::to_string(a.frames) +
                      " frames without the ball (kept as missing, not interpolated)");
  const double sigma = o.u_x, band = o.band_sigmas * o.u_x;
  const int n = s.size();
  // Mean ± scatter/√n of the frames [begin, end) within 3σ of their median (a glitch does not
  // count), σ/√n when fewer than 3.
  const auto stationary = [&](int begin, int end) {
    const double m = Median(std::vector<double>(s.x.begin() + begin, s.x.begin() + end));
    std::vector<double> kept;
    for (int i = begin; i < end; ++i)
      if (std::abs(s.x[i] - m) <= 3 * sigma) kept.push_back(s.x[i]);
    if (kept.empty()) kept.push_back(m);
    const auto [mean, sd] = MeanAndSd(kept, 0, static_cast<int>(kept.size()));
    const int count = static_cast<int>(kept.size());
    return std::pair{Estimate{mean, (count >= 3 ? sd : sigma) / std::sqrt(count)}, sd};
  };

  // Release.
  const std::optional<int> out = FirstDeparture(s.x, false, band, o.confirm_frames, o.reference_frames);
  if (!out) {
    const auto [x, sd] = stationary(0, n);
    a.scatter_at_rest = sd;
    a.rest = TrackEvent{"comes to rest", {s.t[0], std::nullopt}, x,
                        "never moves: mean of all " + std::to_string(n) + " frames found, u = scatter/sqrt(n)"};
    a.fit.unavailable = "the ball never moves (every frame within " + Mm(band) + " of the first ones): no trajectory to fit";
    a.notes.push_back("the ball stays at rest for the whole track: its position is a measured Y");
    return a;
  }
  const int i_out = *out;
  // The position estimates use the frames within a tighter band, min(k, 3)·σ: the k·σ band also
  // holds the first (last) frames of the motion, which bias the mean and inflate the scatter.
  const double tight = std::min(band, 3 * sigma);
  {
    const int still = std::min(i_out, FirstDeparture(s.x, false, tight, o.confirm_frames, o.reference_frames).value_or(n));
    const auto [x, sd] = stationary(0, still);
    if (still >= 3) a.scatter_at_rest = sd;
    a.release = TrackEvent{"release", {s.t[i_out - 1], std::nullopt}, x,
                           "band: the last frame within " + Mm(band) + " of the start, t = " +
                               Printf("%.6g", s.t[i_out - 1]) + " s; position the mean of the first " +
                               std::to_string(still) + " frames, within " + Mm(tight)};
    a.direction = s.x[i_out] > x.value ? 1 : -1;
    if (i_out < 3) a.notes.push_back("the ball moves from the first frames: the release position rests on " +
                                     std::to_string(i_out) + " frame(s)");
  }

  // Final rest: a steady tail, after the release, not at the fall-off.
  int moving_end = n;  // frames [i_out - 1, moving_end) are the motion
  if (const std::optional<int> tail = FirstDeparture(s.x, true, band, o.confirm_frames, o.reference_frames)) {
    const int r0 = n - *tail;
    bool steady_z = true;
    std::vector<double> zt(s.z.begin() + r0, s.z.end());
    const double zm = Median(zt);
    for (double z : zt) steady_z = steady_z && std::abs(z - zm) <= band;
    const std::optional<RestFit> rest = FitRest(s, r0, n, o.rest_frames);
    if (*tail >= o.rest_frames && r0 > i_out && steady_z && rest && rest->x.value < scene.x_max() - band) {
      a.rest = TrackEvent{"comes to rest", {rest->t, std::nullopt}, rest->x,
                          "fit of the final " + std::to_string(*tail) + " frames within " + Mm(band) +
                              ": constant from t on (" + std::to_string(rest->frames) +
                              " frames), a quadratic approach before; u from the scatter"};
      if (!a.scatter_at_rest) a.scatter_at_rest = rest->scatter;
      moving_end = r0;
    }
  }

  // Turning points: a zigzag with the same band and confirmation, on x smoothed by a running
  // median over 2·confirm − 1 frames (a glitch of fewer than `confirm` frames is not an extreme).
  std::vector<double> smooth(n);
  for (int i = 0; i < n; ++i) {
    const int half = o.confirm_frames - 1;
    smooth[i] = Median(std::vector<double>(s.x.begin() + std::max(0, i - half), s.x.begin() + std::min(n, i + half + 1)));
  }
  int dir = a.direction, extreme = i_out, window_begin = 0;
  for (int i = i_out + 1; i < moving_end; ++i) {
    if ((smooth[i] - smooth[extreme]) * dir > 0) {
      extreme = i;
      continue;
    }
    bool reversed = i + o.confirm_frames <= moving_end;
    for (int c = 0; c < o.confirm_frames && reversed; ++c) reversed = (smooth[extreme] - smooth[i + c]) * dir > band;
    if (!reversed) continue;
    std::optional<TrackEvent> e = ParabolaVertex(s, smooth, extreme, 3 * band, dir, sigma, i_out - 1, moving_end - 1);
    if (!e) {
      e = TrackEvent{"turning point", {s.t[extreme], a.frame_interval}, {smooth[extreme], sigma},
                     "the extreme frame (no parabola fits)"};
    }
    a.turning_points.push_back(*e);
    window_begin = extreme;
    while (window_begin < n && s.t[window_begin] < e->t.value) ++window_begin;
    dir = -dir;
    extreme = i;
  }

  // The end: falls off at x_max (moving up) or reaches O (moving down), unless at rest.
  if (!a.rest && n >= 2) {
    double step = 0;
    for (int i = std::max(1, n - 3); i < n; ++i) step = std::max(step, std::abs(s.x[i] - s.x[i - 1]));
    const double tol = band + 2 * step;
    const double last_high = *std::max_element(s.x.end() - std::min(n, o.confirm_frames), s.x.end());
    const double last_low = *std::min_element(s.x.end() - std::min(n, o.confirm_frames), s.x.end());
    const bool falls = dir > 0 && last_high >= scene.x_max() - tol;
    const bool reaches_o = dir < 0 && last_low <= scene.x_low() + tol;
    if (falls || reaches_o) {
      const double edge = falls ? scene.x_max() : scene.x_low();
      int first = n - 1;
      for (int i = std::max(i_out, window_begin); i < n; ++i)
        if (std::abs(s.x[i] - edge) <= band + step) {
          first = i;
          break;
        }
      TrackEvent e{falls ? "falls off" : "reaches O", {s.t[first], a.frame_interval}, {edge, std::nullopt},
                   "the first frame within " + Mm(band + step) + " of " + (falls ? "x_max" : "x_low") +
                       ", u = one frame interval"};
      (falls ? a.fall_off : a.reaches_o) = e;
    }
  }

  // The model fit, from the release (or the last turning point) to the end of the motion.
  int window_end = n;
  if (a.rest && o.fit == TrackFitParameter::kEffectiveG) {
    window_end = moving_end;
    a.fit.notes.push_back("the ball comes to rest, which mu = 0 cannot model: the fit stops where the rest begins "
                          "(fit mu to model it)");
  }
  const double x0_start = a.turning_points.empty() ? a.release->x.value : a.turning_points.back().x.value;
  if (!a.turning_points.empty())
    a.fit.notes.push_back("the fit models the motion after the last turning point (a release from rest there)");
  FitModel(s, window_begin, window_end, dir, scene, o, x0_start, band, &a.fit);

  // Refine the events with the fit where it knows better.
  if (a.fit.available && a.fit.covariance) {
    const FittedParameter* x0 = a.fit.Parameter("x0");
    const FittedParameter* t0 = a.fit.Parameter("t0");
    const auto inflated = [&](const FittedParameter* p) { return *p->se * std::max(1.0, std::sqrt(a.fit.reduced_chi2)); };
    if (a.turning_points.empty()) {
      a.release->method = "model fit (x0, t0); " + a.release->method;
      a.release->t = {t0->value, inflated(t0)};
      a.release->x = {x0->value, inflated(x0)};
    }
    for (const TrackEvent& e : a.fit.model_events)
      for (std::optional<TrackEvent>* end : {&a.fall_off, &a.reaches_o})
        if (*end && (*end)->kind == e.kind) {
          (*end)->t = e.t;
          (*end)->method = "fitted model: t0 + the model's time to get there";
        }
  }
  return a;
}

}  // namespace uphill
