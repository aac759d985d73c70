#include "oracle/motion_reference.hpp"

#include <algorithm>
#include <boost/math/constants/constants.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace uphill::oracle {

TrajectoryReference SpheroidTrajectory(double a_, double b_, double tan_theta, double tan_half_alpha, double g_,
                                       double x0, double v0, double mu_, std::span<const double> xs) {
  using Big = boost::multiprecision::cpp_bin_float_50;
  using boost::multiprecision::asin;
  using boost::multiprecision::atan2;
  using boost::multiprecision::cos;
  using boost::multiprecision::sin;
  using boost::multiprecision::sqrt;
  const Big pi = boost::math::constants::pi<Big>();
  const Big a = a_, b = b_, B = tan_theta, T = tan_half_alpha, g = g_, mu = mu_;
  const Big A = a * T / b, P = 1 + A * A + B * B, sp = sqrt(P);
  const Big x_max = sqrt(a * a + (b / T) * (b / T));
  const Big z_eq = a * sqrt(A * A + B * B) / A;
  const Big psi0 = atan2(B, A * sp), gamma = atan2(A * B, sp), q = A * A / P;
  const Big inertia = Big(2) / 5;
  const Big u_max = pi / 2 - psi0, u_low = -gamma - psi0;
  auto u_of = [&](double x) {
    const Big s = Big(x) / x_max;
    return atan2(s, sqrt((1 - s) * (1 + s))) - psi0;
  };
  auto x_of = [&](const Big& u) { return Big(x_max * sin(psi0 + u)); };
  auto z_of = [&](const Big& u) { return Big(z_eq * cos(u)); };
  auto mass = [&](const Big& u) {
    const Big psi = u + psi0, wg = psi + gamma;
    const Big M = x_max * x_max * cos(psi) * cos(psi) + z_eq * z_eq * sin(u) * sin(u);
    const Big d = cos(wg) * cos(wg) + q * sin(wg) * sin(wg);
    return Big((1 + inertia / d) * M);
  };
  auto kinetic_factor = [&](const Big& u) {
    const Big wg = u + psi0 + gamma;
    return Big(1 + inertia / (cos(wg) * cos(wg) + q * sin(wg) * sin(wg)));
  };
  // dz/du and dx/du (≥ 0 on the rails).
  auto dz = [&](const Big& u) { return Big(-z_eq * sin(u)); };
  auto dx = [&](const Big& u) { return Big(x_max * cos(psi0 + u)); };

  TrajectoryReference out;
  out.times.assign(xs.size(), std::numeric_limits<double>::infinity());
  std::vector<Big> us(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) us[i] = u_of(xs[i]);
  std::vector<bool> done(xs.size(), false);
  for (size_t i = 0; i < xs.size(); ++i)
    if (xs[i] == x0) done[i] = true, out.times[i] = 0;

  Big u_s = u_of(x0), t_s = 0;
  Big e_s = kinetic_factor(u_s) * Big(v0) * Big(v0) / 2;  // ½·K·v² = ½·m·u̇²
  int d;
  if (v0 != 0) {
    d = v0 > 0 ? 1 : -1;
  } else if (abs(dz(u_s)) <= mu * dx(u_s) || dz(u_s) == 0) {
    out.events.push_back({TrajectoryEventKind::kRest, 0.0, x0});
    return out;
  } else {
    d = dz(u_s) < 0 ? 1 : -1;
  }
  for (int leg = 0; leg < 64; ++leg) {
    auto energy = [&](const Big& u) {
      return Big(e_s - g * (z_of(u) - z_of(u_s)) - g * mu * d * (x_of(u) - x_of(u_s)));
    };
    // The first zero of E along direction d, before the end of the rails.
    const Big u_end = d > 0 ? u_max : u_low;
    Big u_stop = u_end;
    bool turns = false;
    constexpr int kScan = 4000;
    Big prev = u_s;
    for (int k = 1; k <= kScan; ++k) {
      const Big u = u_s + (u_end - u_s) * k / kScan;
      if (energy(u) <= 0) {
        std::uintmax_t iterations = 400;
        const auto r = boost::math::tools::toms748_solve(energy, prev < u ? prev : u, prev < u ? u : prev,
                                                         boost::math::tools::eps_tolerance<Big>(160), iterations);
        u_stop = (r.first + r.second) / 2;
        turns = true;
        break;
      }
      prev = u;
    }
    // t over [u_s, u] with u = c + r·sin(πσ/2), σ ∈ [−1, 1].
    const Big c = (u_s + u_stop) / 2, r = (u_stop - u_s) / 2;
    auto sigma_of = [&](const Big& u) {
      Big s = (u - c) / r;
      if (s > 1) s = 1;
      if (s < -1) s = -1;
      return Big(2 * asin(s) / pi);
    };
    auto integrand = [&](const Big& sigma) {
      const Big u = c + r * sin(pi * sigma / 2);
      const Big du = r * pi / 2 * cos(pi * sigma / 2);
      const Big e = energy(u);
      if (e <= 0) return Big(0);
      return Big(sqrt(mass(u) / (2 * e)) * abs(du));
    };
    auto integrate = [&](const Big& s0, const Big& s1) {
      return Big(boost::math::quadrature::gauss_kronrod<Big, 61>::integrate(integrand, s0, s1, 15, Big(1e-35)));
    };
    // Positions first reached on this leg, in the order they are met.
    std::vector<size_t> order;
    for (size_t i = 0; i < xs.size(); ++i)
      if (!done[i] && (us[i] - u_s) * d > 0 && (u_stop - us[i]) * d >= 0) order.push_back(i);
    std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return (us[i] - us[j]) * d < 0; });
    Big t = t_s, sigma_prev = -1;
    for (size_t i : order) {
      const Big sigma = sigma_of(us[i]);
      t += integrate(sigma_prev, sigma);
      sigma_prev = sigma;
      out.times[i] = static_cast<double>(t);
      done[i] = true;
    }
    t += integrate(sigma_prev, 1);
    const double x_stop = static_cast<double>(x_of(u_stop));
    if (!turns) {
      out.events.push_back({d > 0 ? TrajectoryEventKind::kFallOff : TrajectoryEventKind::kReachesO,
                            static_cast<double>(t), x_stop});
      return out;
    }
    if (abs(dz(u_stop)) <= mu * dx(u_stop)) {
      out.events.push_back({TrajectoryEventKind::kRest, static_cast<double>(t), x_stop});
      return out;
    }
    out.events.push_back({TrajectoryEventKind::kTurningPoint, static_cast<double>(t), x_stop});
    u_s = u_stop;
    t_s = t;
    e_s = 0;
    d = dz(u_s) < 0 ? 1 : -1;
  }
  throw std::runtime_error("oracle::SpheroidTrajectory: more than 64 legs");
}

}  // namespace uphill::oracle
