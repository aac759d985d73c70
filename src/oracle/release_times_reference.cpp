#include "oracle/release_times_reference.hpp"

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>

namespace uphill::oracle {

std::vector<double> SpheroidReleaseTimes(double a_, double b_, double tan_theta, double tan_half_alpha,
                                         double g_, double x0, std::span<const double> xs) {
  using Big = boost::multiprecision::cpp_bin_float_50;
  using boost::multiprecision::asinh;
  using boost::multiprecision::atan2;
  using boost::multiprecision::cos;
  using boost::multiprecision::cosh;
  using boost::multiprecision::sin;
  using boost::multiprecision::sinh;
  using boost::multiprecision::sqrt;
  const Big a = a_, b = b_, B = tan_theta, T = tan_half_alpha, g = g_;
  const Big A = a * T / b, P = 1 + A * A + B * B, sp = sqrt(P);
  const Big x_max = sqrt(a * a + (b / T) * (b / T));
  const Big z_eq = a * sqrt(A * A + B * B) / A;
  const Big psi0 = atan2(B, A * sp), gamma = atan2(A * B, sp), q = A * A / P;
  const Big inertia = Big(2) / 5;
  auto u_of = [&](double x) {
    const Big s = Big(x) / x_max;
    return atan2(s, sqrt((1 - s) * (1 + s))) - psi0;
  };
  const Big u0 = u_of(x0);
  auto f = [&](const Big& w) {
    const Big ch = cosh(w / 2), sh = sinh(w / 2);
    const Big a1 = u0 * ch * ch, a2 = u0 * sh * sh, u = a1 + a2, psi = u + psi0;
    const Big M = x_max * x_max * cos(psi) * cos(psi) + z_eq * z_eq * sin(u) * sin(u);
    const Big wg = psi + gamma;
    const Big d = cos(wg) * cos(wg) + q * sin(wg) * sin(wg);
    const Big K = 1 + inertia / d;
    const Big s1 = a1 == 0 ? Big(1) : sin(a1) / a1, s2 = a2 == 0 ? Big(1) : sin(a2) / a2;
    return Big(sqrt(K * M / (g * z_eq * s1 * s2)));
  };
  std::vector<double> out;
  out.reserve(xs.size());
  Big t = 0, w_prev = 0;
  for (double x : xs) {
    const Big u = u_of(x);
    const Big w = 2 * asinh(sqrt((u - u0) / (2 * u0)));
    t += boost::math::quadrature::gauss_kronrod<Big, 61>::integrate(f, w_prev, w, 12, Big(1e-35));
    out.push_back(static_cast<double>(t));
    w_prev = w;
  }
  return out;
}

}  // namespace uphill::oracle
