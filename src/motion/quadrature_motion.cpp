// Method (a): energy quadrature t(σ) = ∫|dt/dσ| dσ in a regularising variable σ (motion.hpp).
//
// A motion is one or two legs; on each leg σ is monotone in time:
//   kCosh   sphere/spheroid below the top: u = u_t·cosh σ (u_t the rest or turning point)
//   kDirect sphere/spheroid over the top (v0 carries it across X), or a cone on level rails:
//           σ = q, dt/dq = sqrt(m/(2·(E − g·z)))  (E − g·z ≥ E − g·z_top > 0: bounded)
//   kSquare double cone: x = x_t + d·σ², d = sign(B) the downhill direction
//   kRods   spheroid on rods, in its normal-angle coordinate q (path_coordinate.hpp, measured
//           from X): q = q0·cosh σ as kCosh, with the height drop from the explicit path
#include <algorithm>
#include <boost/math/quadrature/gauss.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/sinc.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <optional>

#include "model/input_error.hpp"
#include "internal/motion_engine.hpp"
#include "model/number_text.hpp"

namespace uphill::internal {
namespace {

enum class Mode { kCosh, kDirect, kSquare, kRods };

struct Leg {
  double sigma_a, sigma_b;  // σ at the start and the end of the leg
  double t_a, t_b;          // times there (t_b may be +∞)
  double angle_a;
  int sdir;                 // dσ/dt sign
  int xdir;                 // dx/dt sign
};

class QuadratureEngine : public Motion::Engine {
 public:
  QuadratureEngine(const Scene& scene, double x0, const MotionOptions& o)
      : Engine(scene, x0), g_(o.g), tol_(o.tolerance) {
    if (IsEllipse(scene)) {
      ellipse_ = MakeEllipse(scene);
      SetUpEllipse(o.v0);
    } else if (scene.cone() != nullptr) {
      line_.emplace(scene);
      SetUpLine(o.v0);
    } else {
      SetUpRods(o.v0);
    }
  }

  double TimeAt(double x) const override {
    const auto hit = Locate(x);
    return hit ? hit->second : Inf();
  }

  MotionSample AtPosition(double x) const override {
    const auto hit = Locate(x);
    if (!hit) throw InputError("x", "the centre never reaches x = " + ExactText(x) + " m");
    return SampleAt(legs_[hit->first], SigmaOfQ(QOfX(x)), hit->second);
  }

  MotionSample At(double t) const override {
    if (!(t >= 0.0) || !(t <= end_time()))
      throw InputError("t", "must lie in [0, " + ExactText(end_time()) + "] s, the motion (got " + ExactText(t) + " s)");
    if (legs_.empty()) return Rest(t);
    for (const Leg& leg : legs_) {
      if (t > leg.t_b) continue;
      if (t == leg.t_b) return SampleAt(leg, leg.sigma_b, t);
      return SampleAt(leg, SolveSigma(leg, t - leg.t_a), t);
    }
    return SampleAt(legs_.back(), legs_.back().sigma_b, t);
  }

 private:
  // ---- set-up -------------------------------------------------------------------------------
  void SetUpEllipse(double v0) {
    const EllipseCoordinate& e = *ellipse_;
    mode_ = Mode::kCosh;
    const double u0 = e.UOfX(x0_);
    const Geometry g0 = e.At(u0);
    // Level: sin²(u_t/2) = sin²(u0/2) − K0·v0²/(4·g·z_eq).
    const double s0 = std::sin(0.5 * u0);
    const double level = s0 * s0 - g0.kinetic * v0 * v0 / (4.0 * g_ * e.z_eq());
    if (v0 == 0.0 && u0 == 0.0) return Stays();
    if (level < 0.0 || (level == 0.0 && v0 != 0.0 && u0 == 0.0)) {
      // Over the top: kDirect in u, monotone in the direction of v0.
      if (level == 0.0) throw InputError("v0", "puts the body exactly on the separatrix (it would approach X forever)");
      mode_ = Mode::kDirect;
      energy_over_ = -4.0 * g_ * e.z_eq() * level;  // 2·g·(z_top − z_eq) = K0 v0² − 4 g z_eq sin²(u0/2)
      const int dir = v0 > 0 ? 1 : -1;
      direction_ = dir;
      const double u_end = dir > 0 ? e.u_max() : e.u_low();
      AddLeg(u0, u_end, dir, dir, dir > 0 ? MotionEventKind::kFallOff : MotionEventKind::kReachesO);
      return;
    }
    if (level == 0.0) throw InputError("v0", "puts the body exactly on the separatrix (it would approach X forever)");
    const int side = u0 > 0 ? 1 : -1;
    u_t_ = side * 2.0 * std::asin(std::sqrt(level));
    // w0 = acosh(u0/u_t) = 2·asinh(sqrt((u0 − u_t)/(2·u_t))) (no cancellation as u0 → u_t).
    const double w0 = v0 == 0.0 ? 0.0 : 2.0 * std::asinh(std::sqrt(std::max(0.0, (u0 - u_t_) / (2.0 * u_t_))));
    const double u_end = side > 0 ? e.u_max() : e.u_low();
    const double w_end = 2.0 * std::asinh(std::sqrt(std::max(0.0, (u_end - u_t_) / (2.0 * u_t_))));
    const MotionEventKind end_kind = side > 0 ? MotionEventKind::kFallOff : MotionEventKind::kReachesO;
    const int vdir = v0 == 0.0 ? side : (v0 > 0 ? 1 : -1);
    direction_ = vdir;
    if (vdir == side) {
      AddLeg(w0, w_end, 1, side, end_kind);
    } else {
      AddLeg(w0, 0.0, -1, -side, MotionEventKind::kTurningPoint);
      AddLeg(0.0, w_end, 1, side, end_kind);
    }
  }

  void SetUpLine(double v0) {
    const LineCoordinate& l = *line_;
    const Geometry g0 = l.At(x0_);
    const double B = l.B();
    if (B == 0.0) {
      if (v0 == 0.0) return Stays();
      mode_ = Mode::kDirect;
      energy_over_ = g0.kinetic * v0 * v0;  // 2·(E − g z) per unit mass, constant
      direction_ = v0 > 0 ? 1 : -1;
      if (direction_ > 0) {
        AddLeg(x0_, l.x_fall(), 1, 1, MotionEventKind::kFallOff, /*reaches_end=*/false);
      } else {
        AddLeg(x0_, l.x_low(), -1, -1, MotionEventKind::kReachesO);
      }
      return;
    }
    mode_ = Mode::kSquare;
    d_ = B > 0 ? 1 : -1;
    const double rise = g0.kinetic * v0 * v0 / (2.0 * g_ * std::abs(B));  // |x0 − x_t|
    x_t_ = x0_ - d_ * rise;
    const double s0 = std::sqrt(rise);
    auto sigma_of = [&](double x) { return std::sqrt(std::max(0.0, d_ * (x - x_t_))); };
    // Downhill end: the apex (never reached) for d > 0, O for d < 0.
    const bool apex_downhill = d_ > 0;
    const double s_down = sigma_of(apex_downhill ? l.x_fall() : l.x_low());
    const MotionEventKind down_kind = apex_downhill ? MotionEventKind::kFallOff : MotionEventKind::kReachesO;
    const int vdir = v0 == 0.0 ? d_ : (v0 > 0 ? 1 : -1);
    direction_ = vdir;
    if (vdir == d_) {
      AddLeg(s0, s_down, 1, d_, down_kind, !apex_downhill);
      return;
    }
    // Uphill first: the turning point x_t, unless the uphill end comes first.
    const double x_up_end = apex_downhill ? l.x_low() : l.x_fall();
    const bool end_first = apex_downhill ? x_t_ < x_up_end : x_t_ >= x_up_end;
    if (end_first) {
      AddLeg(s0, sigma_of(x_up_end), -1, -d_, apex_downhill ? MotionEventKind::kReachesO : MotionEventKind::kFallOff,
             apex_downhill);
      return;
    }
    AddLeg(s0, 0.0, -1, -d_, MotionEventKind::kTurningPoint);
    AddLeg(0.0, s_down, 1, d_, down_kind, !apex_downhill);
  }

  void SetUpRods(double v0) {
    if (v0 != 0.0)
      throw InputError("v0", "must be 0 for a spheroid on rods with the quadrature method (use the ode method)");
    mode_ = Mode::kRods;
    rods_.emplace(scene_);
    const double X = *scene_.x_eq();
    if (x0_ == X) return Stays();
    d_ = x0_ > X ? 1 : -1;
    direction_ = d_;
    rods_q0_ = rods_->QOfX(x0_);
    const Geometry g0 = rods_->At(rods_q0_);
    rods_z0_ = g0.z;
    rods_slope0_ = std::abs(g0.dz);
    const double q_end = d_ > 0 ? rods_->q_max() : rods_->q_low();
    rods_span_ = std::abs(q_end - rods_q0_);
    AddLeg(0.0, SigmaOfQ(q_end), 1, d_, d_ > 0 ? MotionEventKind::kFallOff : MotionEventKind::kReachesO);
  }

  void Stays() {
    direction_ = 0;
    events_.push_back({MotionEventKind::kRest, 0.0, x0_});
  }

  // Appends a leg from sigma_a to sigma_b; its end is an event (unless reaches_end is false:
  // the cone's apex, never reached).
  void AddLeg(double sa, double sb, int sdir, int xdir, MotionEventKind end_kind, bool reaches_end = true) {
    Leg leg{sa, sb, 0.0, Inf(), 0.0, sdir, xdir};
    if (!legs_.empty()) {
      leg.t_a = legs_.back().t_b;
      leg.angle_a = legs_.back().angle_a + legs_.back().xdir * AngleIntegral(legs_.back().sigma_a, legs_.back().sigma_b);
    }
    if (reaches_end) {
      leg.t_b = leg.t_a + TimeIntegral(sa, sb);
      const double x_end = end_kind == MotionEventKind::kFallOff   ? scene_.x_max()
                           : end_kind == MotionEventKind::kReachesO ? scene_.x_low()
                                                                    : XOfQ(QOfSigma(sb));
      events_.push_back({end_kind, leg.t_b, x_end});
    }
    legs_.push_back(leg);
  }

  // ---- σ ↔ q ↔ x ----------------------------------------------------------------------------
  double QOfSigma(double s) const {
    switch (mode_) {
      case Mode::kCosh: return u_t_ * std::cosh(s);
      case Mode::kDirect: return s;
      case Mode::kSquare: return x_t_ + d_ * s * s;
      case Mode::kRods: return rods_q0_ * std::cosh(s);
    }
    return 0.0;
  }
  double DqDsigma(double s) const {
    switch (mode_) {
      case Mode::kCosh: return u_t_ * std::sinh(s);
      case Mode::kDirect: return 1.0;
      case Mode::kSquare: return 2.0 * d_ * s;
      case Mode::kRods: return rods_q0_ * std::sinh(s);
    }
    return 0.0;
  }
  double QOfX(double x) const {
    if (ellipse_) return ellipse_->UOfX(x);
    if (rods_) return rods_->QOfX(x);
    return x;
  }
  double XOfQ(double q) const {
    if (ellipse_) return ellipse_->XOfU(q);
    if (rods_) return rods_->XOfQ(q);
    return q;
  }
  double SigmaOfQ(double q) const {
    switch (mode_) {
      case Mode::kCosh: return 2.0 * std::asinh(std::sqrt(std::max(0.0, (q - u_t_) / (2.0 * u_t_))));
      case Mode::kDirect: return q;
      case Mode::kSquare: return std::sqrt(std::max(0.0, d_ * (q - x_t_)));
      case Mode::kRods: return 2.0 * std::asinh(std::sqrt(std::max(0.0, (q - rods_q0_) / (2.0 * rods_q0_))));
    }
    return 0.0;
  }

  Geometry GeometryAt(double q) const {
    if (ellipse_) return ellipse_->At(q);
    if (line_) return line_->At(q);
    return rods_->At(q);
  }

  // |dt/dσ| (smooth and bounded on every leg).
  double DtDsigma(double s) const {
    switch (mode_) {
      case Mode::kCosh: {
        const double c = std::cosh(0.5 * s), sh = std::sinh(0.5 * s);
        const Geometry g = ellipse_->At(u_t_ * std::cosh(s));
        using boost::math::sinc_pi;
        return std::sqrt(g.mass / (g_ * ellipse_->z_eq() * sinc_pi(u_t_ * c * c) * sinc_pi(u_t_ * sh * sh)));
      }
      case Mode::kDirect: {
        const Geometry g = GeometryAt(s);
        double two_kinetic = energy_over_;  // 2·(E − g·z) per unit mass
        if (ellipse_) {
          const double h = std::sin(0.5 * s);
          two_kinetic += 4.0 * g_ * ellipse_->z_eq() * h * h;
        }
        return std::sqrt(g.mass / two_kinetic);
      }
      case Mode::kSquare: return std::sqrt(2.0 * line_->At(QOfSigma(s)).mass / (g_ * std::abs(line_->B())));
      case Mode::kRods: {
        // |q0·sinh σ|·sqrt(m/(2·g·(z0 − z))); the drop → |dz/dq(q0)|·(q − q0) as σ → 0, with
        // q − q0 = 2·q0·sinh²(σ/2) (not the difference of two q).
        const Geometry g = rods_->At(QOfSigma(s));
        const double h = std::sinh(0.5 * s), dq = 2.0 * rods_q0_ * h * h;
        const double drop = RodsDrop(dq, g.z);
        const double ratio = !(drop > 0.0) ? std::sqrt(2.0 / (rods_slope0_ * std::abs(rods_q0_)))
                                           : std::abs(rods_q0_ * std::sinh(s)) / std::sqrt(drop);
        return ratio * std::sqrt(g.mass / (2.0 * g_));
      }
    }
    return 0.0;
  }
  // Spheroid on rods: z(q0) − z(q0 + dq) for z = z(q0 + dq) given. Near q0 the difference of two
  // heights would lose its digits (the drop is ~|dz/dq|·|dq|), so within 30 % of the span it is
  // −∫dz/dq by 15-point Gauss–Legendre (Boost; dz/dq is explicit and smooth there: error far
  // below an ulp of the drop).
  double RodsDrop(double dq, double z) const {
    if (std::abs(dq) >= 0.3 * rods_span_) return rods_z0_ - z;
    // On [0, 1] with the width dq as a factor: q0 + dq may round to within an ulp of q0 while
    // dq itself is exact.
    auto slope = [this, dq](double y) { return rods_->At(rods_q0_ + dq * y).dz; };
    return -dq * boost::math::quadrature::gauss<double, 15>::integrate(slope, 0.0, 1.0);
  }
  // |dangle/dσ| = sqrt(M)/R*·|dq/dσ|.
  double DangleDsigma(double s) const {
    const Geometry g = GeometryAt(QOfSigma(s));
    return std::sqrt(g.metric) / g.r_star * std::abs(DqDsigma(s));
  }

  // ∫ f over [min(a,b), max(a,b)] by adaptive Gauss–Kronrod (31 points). The interval is mapped
  // onto [0, 1] first: Boost's GK (1.74) compares an error estimate of the rule on [−1, 1] with
  // a tolerance scaled by the interval's half-width, so on a short interval the relative
  // tolerance could never be met and the recursion ran to max_depth.
  template <class F>
  double Integrate(F f, double a, double b) const {
    if (a == b) return 0.0;
    const double lo = std::min(a, b), width = std::abs(b - a);
    // Spheroid on rods released near X: dz/dq ∝ q there is computed from O(1) terms, so the
    // integrand carries ~ulp/|q0| of rounding noise that no tolerance below it can beat.
    const double noise = mode_ == Mode::kRods ? 4e-17 / std::abs(rods_q0_) : 0.0;
    const double tol = std::max({0.1 * tol_, 1e-14, noise});
    auto unit = [&](double y) { return f(lo + width * y); };
    return width * boost::math::quadrature::gauss_kronrod<double, 31>::integrate(unit, 0.0, 1.0, 12, tol);
  }
  double TimeIntegral(double a, double b) const {
    return Integrate([this](double s) { return DtDsigma(s); }, a, b);
  }
  double AngleIntegral(double a, double b) const {
    return Integrate([this](double s) { return DangleDsigma(s); }, a, b);
  }

  // First leg on which the centre reaches x, and the time.
  std::optional<std::pair<size_t, double>> Locate(double x) const {
    if (!std::isfinite(x)) return std::nullopt;
    if (x == x0_) return std::make_pair(size_t{0}, 0.0);
    if (legs_.empty()) return std::nullopt;
    const double lo_x = scene_.x_low(), hi_x = scene_.x_max();
    if (x < lo_x || x > hi_x) return std::nullopt;
    for (const MotionEvent& e : events_)  // the ends: exact x_max / x_low, known times
      if (e.x == x && (e.kind == MotionEventKind::kFallOff || e.kind == MotionEventKind::kReachesO))
        return std::make_pair(legs_.size() - 1, e.t);
    const double s = SigmaOfQ(QOfX(x));
    for (size_t i = 0; i < legs_.size(); ++i) {
      const Leg& leg = legs_[i];
      const double xa = XOfQ(QOfSigma(leg.sigma_a)), xb = XOfQ(QOfSigma(leg.sigma_b));
      const bool inside = leg.xdir > 0 ? (x >= xa && x <= xb) : (x <= xa && x >= xb);
      if (!inside) continue;
      if (mode_ == Mode::kSquare && line_ && x >= line_->x_fall()) return std::nullopt;
      return std::make_pair(i, leg.t_a + TimeIntegral(leg.sigma_a, s));
    }
    return std::nullopt;
  }

  // σ on leg with elapsed time tau since the leg's start: bracketed Newton, t(σ) accumulated
  // from the previous iterate.
  double SolveSigma(const Leg& leg, double tau) const {
    const double lo = std::min(leg.sigma_a, leg.sigma_b), hi = std::max(leg.sigma_a, leg.sigma_b);
    double last_s = leg.sigma_a, last_t = 0.0;
    auto f = [&](double s) {
      last_t += leg.sdir * TimeIntegral(last_s, s) * (s >= last_s ? 1.0 : -1.0);
      last_s = s;
      return std::make_pair(last_t - tau, leg.sdir * DtDsigma(s));
    };
    double guess;
    if (std::isfinite(leg.t_b)) {
      guess = leg.sigma_a + (leg.sigma_b - leg.sigma_a) * (tau / (leg.t_b - leg.t_a));
    } else {
      guess = leg.sigma_a + leg.sdir * tau / DtDsigma(leg.sigma_a);
      guess = std::min(guess, leg.sigma_a + 0.5 * (leg.sigma_b - leg.sigma_a));
    }
    guess = std::clamp(guess, lo, hi);
    // The apex end of a cone leg (t = ∞) must not be evaluated.
    const double hi_eval = std::isfinite(leg.t_b) ? hi : std::nextafter(hi, lo);
    std::uintmax_t iterations = 200;
    return boost::math::tools::newton_raphson_iterate(f, guess, lo, hi_eval, 52, iterations);
  }

  MotionSample SampleAt(const Leg& leg, double s, double t) const {
    const double q = QOfSigma(s);
    const Geometry g = GeometryAt(q);
    MotionSample out;
    out.t = t;
    out.x = XOfQ(q);
    out.z = g.z;
    const double dtds = DtDsigma(s);
    if (mode_ == Mode::kRods) {
      // Speed from energy (at the fall-off σ = π/2 both dq/dσ and dt/dσ vanish).
      const double h = std::sinh(0.5 * s);
      const double v = std::sqrt(std::max(0.0, 2.0 * g_ * RodsDrop(2.0 * rods_q0_ * h * h, g.z) / g.kinetic));
      const double qdot = leg.xdir * v / std::sqrt(g.metric);  // dx/dq ≥ 0
      out.v = v;
      out.vx = g.dx * qdot;
      out.vz = g.dz * qdot;
    } else {
      const double qdot = leg.sdir * DqDsigma(s) / dtds;
      out.v = std::sqrt(g.metric) * std::abs(qdot);
      out.vx = g.dx * qdot;
      out.vz = g.dz * qdot;
    }
    out.angle = leg.angle_a + leg.xdir * AngleIntegral(leg.sigma_a, s);
    return out;
  }

  MotionSample Rest(double t) const {
    const PathPoint p = scene_.At(x0_);
    MotionSample s;
    s.t = t;
    s.x = x0_;
    s.z = p.z;
    return s;
  }

  double g_, tol_;
  Mode mode_ = Mode::kCosh;
  std::optional<EllipseCoordinate> ellipse_;
  std::optional<LineCoordinate> line_;
  std::vector<Leg> legs_;
  double u_t_ = 0.0, energy_over_ = 0.0, x_t_ = 0.0;
  int d_ = 1;
  std::optional<RodsCoordinate> rods_;
  double rods_q0_ = 0.0, rods_z0_ = 0.0, rods_slope0_ = 0.0, rods_span_ = 0.0;
};

}  // namespace

std::unique_ptr<Motion::Engine> MakeQuadratureEngine(const Scene& scene, double x0,
                                                     const MotionOptions& options) {
  return std::make_unique<QuadratureEngine>(scene, x0, options);
}

}  // namespace uphill::internal
