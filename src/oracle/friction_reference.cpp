#include "oracle/friction_reference.hpp"

#include <cmath>

#include "model/spheroid_on_line_rails.hpp"

namespace uphill::oracle {

FrictionNormalEquations FrictionAt(const FrictionRows& rows, long double mu, long double s) {
  using L = long double;
  FrictionNormalEquations e;
  for (std::size_t i = 0; i < rows.y.size(); ++i) {
    const SpheroidOnLineRails<L> path(rows.a, rows.b, rows.tan_theta[i], rows.tan_half_alpha[i]);
    const L A2 = path.A() * path.A(), PA2 = path.P() * A2;
    const L K = static_cast<L>(rows.tan_theta[i]) + mu * (1 + A2);
    const L x = path.RestX(mu);
    const L j0 = s * path.x_max() * PA2 * (1 + A2) / std::pow(PA2 + K * K, 1.5L);
    const L j1 = x;
    const L w = 1 / (static_cast<L>(rows.u_y[i]) * rows.u_y[i]);
    const L r = rows.y[i] - s * x;
    e.h_mu_mu += w * j0 * j0;
    e.h_mu_s += w * j0 * j1;
    e.h_s_s += w * j1 * j1;
    e.g_mu += w * j0 * r;
    e.g_s += w * j1 * r;
    e.scale_mu += w * std::fabs(j0 * rows.y[i]);
    e.scale_s += w * std::fabs(j1 * rows.y[i]);
  }
  return e;
}

FrictionSolution FrictionMu(const FrictionRows& rows, double mu_start) {
  long double mu = mu_start;
  FrictionNormalEquations e;
  long double previous_step = INFINITY;
  for (int it = 0; it < 200; ++it) {
    e = FrictionAt(rows, mu);
    const long double step = e.g_mu / e.h_mu_mu;
    mu += step;
    const long double size = std::fabs(step);
    if (size == 0 || (size <= 1e-17L * std::fabs(mu) && size >= previous_step)) break;
    previous_step = size;
  }
  e = FrictionAt(rows, mu);
  return {static_cast<double>(mu), static_cast<double>(1 / e.h_mu_mu)};
}

}  // namespace uphill::oracle
