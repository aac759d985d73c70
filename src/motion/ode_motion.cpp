// Method (b): the equation of motion in a smooth coordinate, Boost.Odeint (motion.hpp).
//
// State y = (q/q_s, T·q̇/q_s, angle) in scaled time τ = t/T, T = sqrt(L/g) (L = x_max or x_fall),
// so that every component is O(1) (or O(u0) just after a release near X) for bodies of any size;
// q = ψ − ψ0 (q_s = 1) for sphere/spheroid, q = x (q_s = L) for the double cone, q = β_X − β
// (q_s = 1, β the contact normal angle) for a spheroid on rods.
// The run is split into legs at turning points (the friction force changes sign there); each
// leg is a list of steps of Dormand–Prince 5(4) with step control. A value at a time inside a
// step is recomputed by integrating from the step's start to exactly that time with the
// controlled stepper (full step accuracy, not the 4th-order interpolant); event times are found
// by TOMS 748 on the dense-output interpolant and then polished by Newton steps on such exact
// re-integrations.
#include <algorithm>
#include <array>
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <optional>

#include "model/input_error.hpp"
#include "internal/motion_engine.hpp"
#include "model/number_text.hpp"

namespace uphill::internal {
namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 3>;
using Stepper = odeint::runge_kutta_dopri5<State>;

struct Step {
  double tau0, tau1;  // scaled times (tau1 possibly cut at an event)
  State y0;
  double dtau;        // step size the stepper tried first (reproduces the step)
  int fdir;           // direction of motion (friction sign) on this step
};

class OdeEngine : public Motion::Engine {
 public:
  OdeEngine(const Scene& scene, double x0, const MotionOptions& o)
      : Engine(scene, x0), g_(o.g), mu_(o.mu), rel_(o.tolerance) {
    if (IsEllipse(scene)) {
      ellipse_ = MakeEllipse(scene);
      qs_ = 1.0;
      length_ = ellipse_->x_max();
      q_hi_ = ellipse_->u_max();
      q_lo_ = ellipse_->u_low();
    } else if (scene.cone() != nullptr) {
      line_.emplace(scene);
      length_ = line_->x_fall();
      qs_ = length_;
      // The apex takes infinitely long: stop where R* has shrunk to 1e-6 of its range.
      q_hi_ = (line_->x_fall() - 1e-6 * (line_->x_fall() - line_->x_low())) / qs_;
      apex_horizon_ = true;
      q_lo_ = line_->x_low() / qs_;
    } else {
      // Spheroid on rods: q = β_X − β (path_coordinate.hpp), explicit in β.
      rods_.emplace(scene);
      qs_ = 1.0;
      length_ = scene.x_max();
      q_hi_ = rods_->q_max();
      q_lo_ = rods_->q_low();
    }
    time_scale_ = std::sqrt(length_ / g_);
    Run(o.v0);
  }

  double TimeAt(double x) const override {
    if (x == x0_) return 0.0;
    if (!(x >= scene_.x_low() && x <= scene_.x_max())) return Inf();
    for (const MotionEvent& e : events_)  // the ends are located exactly when the run stops
      if (e.x == x && (e.kind == MotionEventKind::kFallOff || e.kind == MotionEventKind::kReachesO)) return e.t;
    const double target = QOf(x);
    for (size_t i = 0; i < steps_.size(); ++i) {
      const Step& s = steps_[i];
      const double qa = s.y0[0], qb = StateAt(s, s.tau1)[0];
      const bool inside = (qa - target) * (qb - target) <= 0.0;
      if (!inside || qa == qb) continue;
      if (qb == target) return s.tau1 * time_scale_;
      return FindTau(s, 0, target) * time_scale_;
    }
    return Inf();
  }

  MotionSample At(double t) const override {
    if (!(t >= 0.0) || !(t <= end_time()))
      throw InputError("t", "must lie in [0, " + ExactText(end_time()) + "] s, the motion (got " + ExactText(t) + " s)");
    const double tau = t / time_scale_;
    if (steps_.empty()) return Sample(t, y_start_);
    for (const Step& s : steps_)
      if (tau <= s.tau1) return Sample(t, StateAt(s, std::max(tau, s.tau0)));
    // After the last step: at rest (μ > 0 or stays), or beyond the cone's horizon.
    if (apex_horizon_ && !rest_)
      throw InputError("t", "is beyond the integrated range (the cone is within 1e-6 of its apex at t = " +
                                ExactText(steps_.back().tau1 * time_scale_) + " s)");
    return Sample(t, y_end_);
  }

 private:
  // ---- geometry -----------------------------------------------------------------------------
  double QOf(double x) const {
    if (ellipse_) return ellipse_->UOfX(x);
    if (rods_) return rods_->QOfX(x);
    return x / qs_;
  }
  double XOf(double q) const {
    if (ellipse_) return ellipse_->XOfU(q);
    if (rods_) return rods_->XOfQ(q);
    return q * qs_;
  }
  Geometry GeometryAt(double q) const {
    if (ellipse_) return ellipse_->At(q);
    if (rods_) return rods_->At(q);
    return line_->At(q * qs_);
  }

  void Rhs(const State& y, State& dy, int fdir) const {
    const Geometry g = GeometryAt(y[0]);
    const double T = time_scale_;
    const double qdot = y[1] * qs_ / T;  // physical dq/dt
    const double force = -g_ * g.dz - 0.5 * g.dmass * qdot * qdot - g_ * mu_ * std::abs(g.dx) * fdir;
    dy[0] = y[1];
    dy[1] = T * T / qs_ * force / g.mass;
    dy[2] = T * std::sqrt(g.metric) / g.r_star * qdot;
  }

  MotionSample Sample(double t, const State& y) const {
    const Geometry g = GeometryAt(y[0]);
    const double qdot = y[1] * qs_ / time_scale_;
    MotionSample s;
    s.t = t;
    s.x = XOf(y[0]);
    s.z = g.z;
    s.v = std::sqrt(g.metric) * std::abs(qdot);
    s.vx = g.dx * qdot;
    s.vz = g.dz * qdot;
    s.angle = y[2];
    return s;
  }

  // ---- integration --------------------------------------------------------------------------
  auto System(int fdir) const {
    return [this, fdir](const State& y, State& dy, double) { Rhs(y, dy, fdir); };
  }
  double AbsTol() const { return rel_ * 1e-3 * abs_scale_; }

  // The state at tau in step s, integrated from the step's start with step control.
  State StateAt(const Step& s, double tau) const {
    State y = s.y0;
    if (tau == s.tau0) return y;
    auto stepper = odeint::make_controlled(AbsTol(), rel_, Stepper());
    odeint::integrate_adaptive(stepper, System(s.fdir), y, s.tau0, tau, std::min(s.dtau, tau - s.tau0));
    return y;
  }

  // Root of y_k(τ) = c in step s (a sign change between its ends): TOMS 748 on the dense
  // output, then Newton polish on exactly re-integrated states (slope dy_k/dτ from the RHS).
  double FindTau(const Step& s, int k, double c) const {
    auto dense = odeint::make_dense_output(AbsTol(), rel_, Stepper());
    dense.initialize(s.y0, s.tau0, s.dtau);
    dense.do_step(System(s.fdir));
    State y;
    auto f = [&](double tau) {
      dense.calc_state(tau, y);
      return y[k] - c;
    };
    const double a = s.tau0, b = std::min(s.tau1, dense.current_time());
    const double fa = s.y0[k] - c, fb = f(b);
    double tau;
    if (fa == 0.0) {
      tau = a;
    } else if (fb == 0.0 || fa * fb > 0.0) {
      tau = b;
    } else {
      std::uintmax_t iterations = 100;
      auto r = boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(50),
                                                 iterations);
      tau = 0.5 * (r.first + r.second);
    }
    const double limit = s.tau1 + (s.tau1 - s.tau0);
    for (int n = 0; n < 3; ++n) {
      const State ys = StateAt(s, tau);
      State dy;
      Rhs(ys, dy, s.fdir);
      const double val = ys[k] - c;
      if (val == 0.0 || dy[k] == 0.0 || !std::isfinite(dy[k])) break;
      const double next = std::clamp(tau - val / dy[k], s.tau0, limit);
      if (next == tau) break;
      tau = next;
    }
    return tau;
  }

  void Run(double v0) {
    const double q0 = QOf(x0_);
    Geometry g0 = GeometryAt(q0);
    // q̇0 from the speed: v = sqrt(M)·|q̇|, sign from the direction of x (dx/dq ≥ 0).
    const double qdot0 = v0 / std::sqrt(g0.metric);
    y_start_ = {q0, qdot0 * time_scale_ / qs_, 0.0};
    y_end_ = y_start_;
    int dir;
    if (v0 != 0.0) {
      dir = v0 > 0 ? 1 : -1;
    } else if (std::abs(g0.dz) <= mu_ * std::abs(g0.dx) || g0.dz == 0.0) {
      direction_ = 0;
      rest_ = true;
      events_.push_back({MotionEventKind::kRest, 0.0, x0_});
      return;
    } else {
      dir = g0.dz < 0 ? 1 : -1;
    }
    direction_ = dir;
    abs_scale_ = std::max({std::abs(q0), std::abs(y_start_[1]), 1e-300});
    if (line_) abs_scale_ = 1.0;
    abs_scale_ = std::min(abs_scale_, 1.0);

    State y = y_start_;
    double tau = 0.0;
    double dtau = 1e-3;
    for (int leg = 0; leg < 10000; ++leg) {
      auto dense = odeint::make_dense_output(AbsTol(), rel_, Stepper());
      dense.initialize(y, tau, dtau);
      bool leg_done = false;
      for (int n = 0; n < 1000000 && !leg_done; ++n) {
        Step s{dense.current_time(), 0.0, dense.current_state(), dense.current_time_step(), dir};
        const auto [t0, t1] = dense.do_step(System(dir));
        s.tau1 = t1;
        (void)t0;
        const State y1 = dense.current_state();
        // Events in this step: boundary crossings and a sign change of q̇.
        const bool hi = y1[0] >= q_hi_, lo = y1[0] <= q_lo_;
        const bool turn = y1[1] * dir <= 0.0;
        if (!hi && !lo && !turn) {
          steps_.push_back(s);
          continue;
        }
        std::optional<double> tau_b, tau_t;
        if (hi) tau_b = FindTau(s, 0, q_hi_);
        if (lo) tau_b = FindTau(s, 0, q_lo_);
        if (turn) tau_t = FindTau(s, 1, 0.0);
        if (tau_b && (!tau_t || *tau_b <= *tau_t)) {
          s.tau1 = *tau_b;
          steps_.push_back(s);
          y_end_ = StateAt(s, s.tau1);
          if (hi) y_end_[0] = q_hi_;
          if (lo) y_end_[0] = q_lo_;
          if (!(hi && apex_horizon_))
            events_.push_back({hi ? MotionEventKind::kFallOff : MotionEventKind::kReachesO, s.tau1 * time_scale_,
                               hi ? scene_.x_max() : scene_.x_low()});
          return;
        }
        s.tau1 = *tau_t;
        steps_.push_back(s);
        y = StateAt(s, s.tau1);
        y[1] = 0.0;
        tau = s.tau1;
        dtau = std::max(s.dtau, 1e-12);
        const Geometry g = GeometryAt(y[0]);
        const double x = XOf(y[0]);
        if (std::abs(g.dz) <= mu_ * std::abs(g.dx)) {
          events_.push_back({MotionEventKind::kRest, tau * time_scale_, x});
          y_end_ = y;
          rest_ = true;
          return;
        }
        events_.push_back({MotionEventKind::kTurningPoint, tau * time_scale_, x});
        dir = g.dz < 0 ? 1 : -1;
        leg_done = true;
      }
      if (!leg_done) throw std::runtime_error("motion: ODE integration did not finish");
    }
    throw std::runtime_error("motion: too many turning points");
  }

  double g_, mu_, rel_;
  std::optional<EllipseCoordinate> ellipse_;
  std::optional<LineCoordinate> line_;
  std::optional<RodsCoordinate> rods_;
  double qs_ = 1.0, length_ = 1.0, time_scale_ = 1.0, q_hi_ = 0.0, q_lo_ = 0.0, abs_scale_ = 1.0;
  bool apex_horizon_ = false, rest_ = false;
  State y_start_{}, y_end_{};
  std::vector<Step> steps_;
};

}  // namespace

std::unique_ptr<Motion::Engine> MakeOdeEngine(const Scene& scene, double x0, const MotionOptions& options) {
  return std::make_unique<OdeEngine>(scene, x0, options);
}

}  // namespace uphill::internal
