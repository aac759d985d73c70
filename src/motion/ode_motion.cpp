// Method (b): the equation of motion in a smooth coordinate, integrated once (motion.hpp).
//
// State y = (q/q_s, T·q̇/q_s, angle) in scaled time τ = t/T, T = sqrt(L/g) (L = x_max or x_fall),
// so that every component is O(1) (or O(u0) just after a release near X) for bodies of any size;
// q = ψ − ψ0 (q_s = 1) for sphere/spheroid, q = x (q_s = L) for the double cone, q = β_X − β
// (q_s = 1, β the contact normal angle) for a spheroid on rods.
//
// One integration by Boost.Odeint's Dormand–Prince 5(4) (runge_kutta_dopri5 under
// controlled_runge_kutta, std::array state) keeps the dense output of every accepted step: a copy
// of the stepper's stages and the step's end states and derivatives (Odeint's own calc_state, a
// 4th-order continuous extension), so that every later query is answered from it without
// integrating again: At(t) finds its step by binary search over the step ends; TimeAt(x) finds
// the leg and, q being monotone on a leg, the step by binary search over q, then the root of
// q(τ) = q(x) by TOMS 748 (Boost.Math) on the dense output. The events are located the same way
// while integrating: a sign change of q̇ (turning point; at rest for good when |z'| ≤ μ there), q
// crossing the fall-off or O. The run is split into legs at turning points (the friction force
// changes sign there, so each leg's right-hand side is smooth).
// No allocation per step: the steps' vector grows geometrically (reserved up front for a typical
// run); Odeint works on std::array states.
#include <algorithm>
#include <array>
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "internal/motion_engine.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill::internal {
namespace {

using State = std::array<double, 3>;
namespace odeint = boost::numeric::odeint;
using Dopri5 = odeint::runge_kutta_dopri5<State>;

// The dense output of one accepted Dormand–Prince step from τ0 to τ0 + h: Odeint's calc_state
// needs the stepper's inner stages (kept in the stepper object: copied) and both ends.
struct Dense {
  Dopri5 stages;
  State y0, dy0, y1, dy1;
  double tau0, h;
  State At(double tau) const {
    State y;
    stages.calc_state(tau, y, y0, dy0, tau0, y1, dy1, tau0 + h);
    return y;
  }
  double Component(int k, double tau) const { return At(tau)[k]; }
};

// The path in the state's coordinate (q/q_s): geometry and the conversions to and from x.
struct EllipsePath {
  EllipseCoordinate e;
  static constexpr double kScale = 1.0;
  Geometry At(double q) const { return e.At(q); }
  double QOfX(double x) const { return e.UOfX(x); }
  double XOfQ(double q) const { return e.XOfU(q); }
};
struct ConePath {
  LineCoordinate line;
  double scale;  // q_s = x_fall: the state holds x/x_fall
  Geometry At(double q) const { return line.At(q * scale); }
  double QOfX(double x) const { return x / scale; }
  double XOfQ(double q) const { return q * scale; }
};
struct RodsPath {
  RodsCoordinate rods;
  static constexpr double kScale = 1.0;
  Geometry At(double q) const { return rods.At(q); }
  double QOfX(double x) const { return rods.QOfX(x); }
  double XOfQ(double q) const { return rods.XOfQ(q); }
};

// One accepted step: its dense output, and where it ends (τ0 + h, or earlier at an event).
struct Segment {
  Dense dense;
  double tau1;
};
// Steps [begin, end) of a leg, on which the motion's direction (the sign of q̇) is `dir`.
struct Leg {
  std::size_t begin, end;
  int dir;
};

// Root of p(τ) = 0 on [a, b] with p(a), p(b) of opposite signs (or one of them 0): TOMS 748 to
// a few ulp of τ.
template <class P>
double Root(const P& p, double a, double b, double pa, double pb) {
  if (pa == 0.0) return a;
  if (pb == 0.0) return b;
  std::uintmax_t iterations = 64;
  const auto r = boost::math::tools::toms748_solve(p, a, b, pa, pb, boost::math::tools::eps_tolerance<double>(52),
                                                   iterations);
  return 0.5 * (r.first + r.second);
}

template <class Path>
class OdeEngine final : public Motion::Engine {
 public:
  OdeEngine(const Scene& scene, double x0, const MotionOptions& o, Path path, double length, double q_lo,
            double q_hi, bool apex_horizon)
      : Engine(scene, x0),
        path_(std::move(path)),
        g_(o.g),
        mu_(o.mu),
        rel_(o.tolerance),
        time_scale_(std::sqrt(length / o.g)),
        q_lo_(q_lo),
        q_hi_(q_hi),
        apex_horizon_(apex_horizon) {
    Run(o.v0);
  }

  double TimeAt(double x) const override {
    if (x == x0_) return 0.0;
    if (!(x >= scene_.x_low() && x <= scene_.x_max())) return Inf();
    for (const MotionEvent& e : events_)  // the ends are located exactly when the run stops
      if (e.x == x && (e.kind == MotionEventKind::kFallOff || e.kind == MotionEventKind::kReachesO)) return e.t;
    const double target = path_.QOfX(x);
    for (const Leg& leg : legs_) {
      if (leg.begin == leg.end) continue;
      const double qa = segments_[leg.begin].dense.y0[0], qb = SegmentEnd(leg.end - 1)[0];
      if ((qa - target) * (qb - target) > 0.0 || qa == qb) continue;
      // The last step starting on the near side of the target (q is monotone on the leg).
      const auto first = segments_.begin() + static_cast<std::ptrdiff_t>(leg.begin);
      const auto last = segments_.begin() + static_cast<std::ptrdiff_t>(leg.end);
      const auto after = std::partition_point(first + 1, last, [&](const Segment& s) {
        return (s.dense.y0[0] - target) * leg.dir <= 0.0;
      });
      const Segment& s = *(after - 1);
      const double pa = s.dense.y0[0] - target, pb = SegmentEnd(static_cast<std::size_t>(after - 1 - segments_.begin()))[0] - target;
      if (pa * pb > 0.0) continue;  // rounding at a step boundary: not in this leg after all
      const double tau = Root([&](double t) { return s.dense.Component(0, t) - target; }, s.dense.tau0, s.tau1, pa, pb);
      return tau * time_scale_;
    }
    return Inf();
  }

  MotionSample At(double t) const override {
    if (!(t >= 0.0) || !(t <= end_time()))
      throw InputError("t", "must lie in [0, " + ExactText(end_time()) + "] s, the motion (got " + ExactText(t) + " s)");
    const double tau = t / time_scale_;
    if (segments_.empty()) return Sample(t, y_start_);
    if (tau >= segments_.back().tau1) {
      // At the end event or after it: at rest (μ > 0, or stays), or beyond the cone's horizon.
      if (apex_horizon_ && !rest_ && tau > segments_.back().tau1)
        throw InputError("t", "is beyond the integrated range (the cone is within 1e-6 of its apex at t = " +
                                  ExactText(segments_.back().tau1 * time_scale_) + " s)");
      return Sample(t, y_end_);
    }
    const auto s = std::partition_point(segments_.begin(), segments_.end(),
                                        [&](const Segment& seg) { return seg.tau1 < tau; });
    return Sample(t, s->dense.At(std::max(tau, s->dense.tau0)));
  }

 private:
  // The equation of motion in the scaled state (see the file comment); fdir the direction of
  // motion on the current leg, which the resisting force opposes.
  void Rhs(const State& y, State& dy, int fdir) const {
    const Geometry g = path_.At(y[0]);
    const double T = time_scale_, qs = Scale();
    const double qdot = y[1] * qs / T;  // physical dq/dt
    const double force = -g_ * g.dz - 0.5 * g.dmass * qdot * qdot - g_ * mu_ * std::abs(g.dx) * fdir;
    dy[0] = y[1];
    dy[1] = T * T / qs * force / g.mass;
    dy[2] = T * std::sqrt(g.metric) / g.r_star * qdot;
  }
  double Scale() const {
    if constexpr (std::is_same_v<Path, ConePath>) return path_.scale;
    else return Path::kScale;
  }

  MotionSample Sample(double t, const State& y) const {
    const Geometry g = path_.At(y[0]);
    const double qdot = y[1] * Scale() / time_scale_;
    MotionSample s;
    s.t = t;
    s.x = path_.XOfQ(y[0]);
    s.z = g.z;
    s.v = std::sqrt(g.metric) * std::abs(qdot);
    s.vx = g.dx * qdot;
    s.vz = g.dz * qdot;
    s.angle = y[2];
    return s;
  }

  State SegmentEnd(std::size_t i) const { return segments_[i].dense.At(segments_[i].tau1); }

  void Run(double v0) {
    const double q0 = path_.QOfX(x0_);
    const Geometry g0 = path_.At(q0);
    // q̇0 from the speed: v = sqrt(M)·|q̇|, sign from the direction of x (dx/dq ≥ 0).
    const double qdot0 = v0 / std::sqrt(g0.metric);
    y_start_ = {q0, qdot0 * time_scale_ / Scale(), 0.0};
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
    // Absolute tolerance: relative to the state's own size at the start, so that a release within
    // 1e-9 of X (q0 ≈ 1e-9) keeps its relative accuracy; never above the O(1) scale of the path.
    double abs_scale = std::max({std::abs(q0), std::abs(y_start_[1]), 1e-300});
    if (std::is_same_v<Path, ConePath>) abs_scale = 1.0;
    abs_scale = std::min(abs_scale, 1.0);
    auto controlled = odeint::make_controlled(rel_ * 1e-3 * abs_scale, rel_, Dopri5());
    segments_.reserve(256);

    struct System {
      const OdeEngine* engine;
      int dir;
      void operator()(const State& y, State& dy, double) const { engine->Rhs(y, dy, dir); }
    };
    System system{this, dir};
    State y = y_start_, dy;
    double tau = 0.0;
    // First step: a fraction of the O(1) scaled time, from the order of the method; the control
    // adapts it within a few steps.
    double dtau = 0.1 * std::pow(rel_, 0.2);
    system(y, dy, tau);
    constexpr std::size_t kMaxSteps = 1000000;
    for (int leg = 0; leg < 10000; ++leg) {
      legs_.push_back({segments_.size(), segments_.size(), dir});
      for (;;) {
        if (segments_.size() >= kMaxSteps) throw std::runtime_error("motion: ODE integration did not finish");
        Segment s;
        s.dense.y0 = y;
        s.dense.dy0 = dy;
        s.dense.tau0 = tau;
        for (int tries = 0;; ++tries) {
          const double before = dtau;
          if (controlled.try_step(system, y, dy, tau, s.dense.y1, s.dense.dy1, dtau) == odeint::success) {
            s.dense.h = before;
            break;
          }
          if (tries > 100 || !(dtau > 0.0)) throw std::runtime_error("motion: ODE step size underflow");
        }
        s.dense.stages = controlled.stepper();
        y = s.dense.y1;
        dy = s.dense.dy1;
        s.tau1 = tau;
        const State& y1 = s.dense.y1;
        // Events in this step: boundary crossings and a sign change of q̇.
        const bool hi = y1[0] >= q_hi_, lo = y1[0] <= q_lo_;
        const bool turn = y1[1] * dir <= 0.0;
        if (!hi && !lo && !turn) {
          segments_.push_back(s);
          legs_.back().end = segments_.size();
          continue;
        }
        const double a = s.dense.tau0, b = s.tau1;
        const double bound = hi ? q_hi_ : q_lo_;
        double tau_b = Inf(), tau_t = Inf();
        if (hi || lo)
          tau_b = Root([&](double t) { return s.dense.Component(0, t) - bound; }, a, b, s.dense.y0[0] - bound,
                       y1[0] - bound);
        if (turn)
          tau_t = Root([&](double t) { return s.dense.Component(1, t); }, a, b, s.dense.y0[1], y1[1]);
        if (tau_b <= tau_t) {
          s.tau1 = tau_b;
          segments_.push_back(s);
          legs_.back().end = segments_.size();
          y_end_ = s.dense.At(tau_b);
          y_end_[0] = bound;
          if (!(hi && apex_horizon_))
            events_.push_back({hi ? MotionEventKind::kFallOff : MotionEventKind::kReachesO, tau_b * time_scale_,
                               hi ? scene_.x_max() : scene_.x_low()});
          return;
        }
        s.tau1 = tau_t;
        segments_.push_back(s);
        legs_.back().end = segments_.size();
        y = s.dense.At(tau_t);
        y[1] = 0.0;
        const Geometry g = path_.At(y[0]);
        const double x = path_.XOfQ(y[0]);
        if (std::abs(g.dz) <= mu_ * std::abs(g.dx)) {
          events_.push_back({MotionEventKind::kRest, tau_t * time_scale_, x});
          y_end_ = y;
          rest_ = true;
          return;
        }
        events_.push_back({MotionEventKind::kTurningPoint, tau_t * time_scale_, x});
        dir = g.dz < 0 ? 1 : -1;
        system.dir = dir;
        tau = tau_t;
        system(y, dy, tau);
        break;
      }
    }
    throw std::runtime_error("motion: too many turning points");
  }

  Path path_;
  double g_, mu_, rel_;
  double time_scale_, q_lo_, q_hi_;
  bool apex_horizon_, rest_ = false;
  State y_start_{}, y_end_{};
  std::vector<Segment> segments_;
  std::vector<Leg> legs_;
};

}  // namespace

std::unique_ptr<Motion::Engine> MakeOdeEngine(const Scene& scene, double x0, const MotionOptions& options) {
  if (IsEllipse(scene)) {
    EllipsePath path{MakeEllipse(scene)};
    const double length = path.e.x_max(), lo = path.e.u_low(), hi = path.e.u_max();
    return std::make_unique<OdeEngine<EllipsePath>>(scene, x0, options, std::move(path), length, lo, hi, false);
  }
  if (scene.cone() != nullptr) {
    const LineCoordinate line(scene);
    const double length = line.x_fall();
    // The apex takes infinitely long: stop where R* has shrunk to 1e-6 of its range.
    const double hi = (line.x_fall() - 1e-6 * (line.x_fall() - line.x_low())) / length;
    const double lo = line.x_low() / length;
    return std::make_unique<OdeEngine<ConePath>>(scene, x0, options, ConePath{line, length}, length, lo, hi, true);
  }
  // Spheroid on rods: q = β_X − β (path_coordinate.hpp), explicit in β.
  RodsPath path{RodsCoordinate(scene)};
  const double lo = path.rods.q_low(), hi = path.rods.q_max();
  return std::make_unique<OdeEngine<RodsPath>>(scene, x0, options, std::move(path), scene.x_max(), lo, hi, false);
}

}  // namespace uphill::internal
