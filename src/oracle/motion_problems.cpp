#include "oracle/motion_problems.hpp"

#include <cmath>

namespace uphill::oracle {

MotionProblem MakeMotionProblem(MotionProblemKind kind, int n) {
  constexpr double kA = 0.020, kB = 0.032, kG = 9.80665;
  const Rails rails = Rails::FromAngles(1.0 * M_PI / 180, 30.0 * M_PI / 180);
  const Scene s(Body::Spheroid(kA, kB), rails);
  const double x_eq = *s.x_eq(), x0 = 1.05 * x_eq, x_end = 0.99 * s.x_max();
  MotionProblem p{"release", kA, kB, kG, s, x0, 0.0, 0.0, {}, {}};
  auto reference = [&](const std::vector<double>& xs) {
    return SpheroidTrajectory(kA, kB, rails.tan_theta, rails.tan_half_alpha, kG, p.x0, p.v0, p.mu, xs);
  };
  if (kind == MotionProblemKind::kRelease) {
    for (int i = 1; i <= n; ++i) p.xs.push_back(x0 + (x_end - x0) * i / n);
  } else if (kind == MotionProblemKind::kTurning) {
    p.name = "turns";
    const double v_over = std::sqrt(2 * kG * (s.At(x_eq).z - s.At(x0).z) / s.KineticFactor(x0));
    p.v0 = -0.5 * v_over;
    const double x_turn = reference({}).events.front().x;
    for (int i = 1; i <= n / 2; ++i) p.xs.push_back(x_turn + 0.9 * (x0 - x_turn) * i / (n / 2));
    for (int i = 1; i <= n / 2; ++i) p.xs.push_back(x0 + (x_end - x0) * i / (n / 2));
  } else {
    p.name = "comes to rest";
    const double h = 1e-7 * x0;
    p.mu = 0.5 * std::abs((s.At(x0 + h).z - s.At(x0 - h).z) / (2 * h));
    const double x_stop = 0.5 * (x_eq + s.Rest(p.mu)->high);
    p.v0 = -std::sqrt(2 * kG * (s.At(x_stop).z - s.At(x0).z + p.mu * (x0 - x_stop)) / s.KineticFactor(x0));
    const double x_rest = reference({}).events.front().x;
    for (int i = 1; i <= n; ++i) p.xs.push_back(x_rest + 0.9 * (x0 - x_rest) * i / n);
  }
  p.reference = reference(p.xs);
  return p;
}

}  // namespace uphill::oracle
