#include "oracle/line_references.hpp"

#include <algorithm>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <stdexcept>

namespace uphill::oracle {
namespace {

using Big = boost::multiprecision::cpp_bin_float_50;
using L = long double;

LineSolution LeastSquares(LineRows d, bool weighted) {
  const std::size_t n = d.size();
  if (n < 3 || d.y.size() != n || (weighted && d.u_y.size() != n))
    throw std::invalid_argument("oracle: least squares needs >= 3 rows with matching columns");
  std::vector<Big> w(n);
  Big sw = 0, swx = 0, swy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    w[i] = weighted ? Big(1) / (Big(d.u_y[i]) * d.u_y[i]) : Big(1);
    sw += w[i];
    swx += w[i] * d.x[i];
    swy += w[i] * d.y[i];
  }
  const Big xm = swx / sw, ym = swy / sw;
  Big sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Big dx = d.x[i] - xm;
    sxx += w[i] * dx * dx;
    sxy += w[i] * dx * (d.y[i] - ym);
  }
  const Big k = sxy / sxx, c = ym - k * xm;
  Big chi2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Big r = d.y[i] - c - k * d.x[i];
    chi2 += w[i] * r * r;
  }
  LineSolution s;
  s.k = static_cast<double>(k);
  s.c = static_cast<double>(c);
  s.var_k = static_cast<double>(1 / sxx);
  s.var_c = static_cast<double>(1 / sw + xm * xm / sxx);
  s.cov_kc = static_cast<double>(-xm / sxx);
  s.chi2 = static_cast<double>(chi2);
  s.dof = static_cast<int>(n) - 2;
  return s;
}

// Newton on Huber's objective with row scales sigma_i = 1/inv_sigma[i] on X centred at xc
// (x = X − xc), from and to (k, c) with c the intercept at xc.
void HuberNewton(LineRows d, const std::vector<L>& x, const std::vector<L>& inv_sigma, L delta,
                 L& k, L& c) {
  const std::size_t n = d.size();
  const auto objective = [&](L kk, L cc) {
    L f = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L s = std::fabs((d.y[i] - cc - kk * x[i]) * inv_sigma[i]);
      f += s <= delta ? s * s : 2 * delta * s - delta * delta;
    }
    return f;
  };
  L f = objective(k, c);
  for (int it = 0; it < 200; ++it) {
    L g0 = 0, g1 = 0, h00 = 0, h01 = 0, h11 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L s = (d.y[i] - c - k * x[i]) * inv_sigma[i];
      const L w = std::fabs(s) <= delta ? 1 : delta / std::fabs(s);  // IRLS weight
      const L psi = w * s * inv_sigma[i];                                // ½ dρ/dr
      g0 += psi * x[i];
      g1 += psi;
      if (std::fabs(s) <= delta) {  // Newton: only inliers curve the objective
        const L q = inv_sigma[i] * inv_sigma[i];
        h00 += q * x[i] * x[i];
        h01 += q * x[i];
        h11 += q;
      }
    }
    const L det = h00 * h11 - h01 * h01;
    L dk = (h11 * g0 - h01 * g1) / det, dc = (h00 * g1 - h01 * g0) / det;
    bool moved = false;
    for (int half = 0; half < 60; ++half) {
      const L fn = objective(k + dk, c + dc);
      if (fn <= f) {
        moved = fn < f || dk != 0 || dc != 0;
        k += dk;
        c += dc;
        f = fn;
        break;
      }
      dk /= 2;
      dc /= 2;
    }
    if (!moved || (std::fabs(dk) <= 1e-18L * std::fabs(k) && std::fabs(dc) <= 1e-18L * (std::fabs(c) + 1)))
      break;
  }
}

// The solution at (k, c) (c at xc) with the IRLS covariance at its final weights.
LineSolution HuberSolution(LineRows d, const std::vector<L>& x, const std::vector<L>& inv_sigma,
                           double xc, L delta, L k, L c) {
  const std::size_t n = d.size();
  L h00 = 0, h01 = 0, h11 = 0, chi2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L s = (d.y[i] - c - k * x[i]) * inv_sigma[i];
    const L weight = std::fabs(s) <= delta ? 1 : delta / std::fabs(s);
    const L w = weight * inv_sigma[i] * inv_sigma[i];
    h00 += w * x[i] * x[i];
    h01 += w * x[i];
    h11 += w;
    chi2 += weight * s * s;
  }
  const L det = h00 * h11 - h01 * h01;
  const L var_k = h11 / det, var_cc = h00 / det, cov = -h01 / det;
  const L lxc = xc;
  LineSolution out;
  out.k = static_cast<double>(k);
  out.c = static_cast<double>(c - k * lxc);  // c = c_centred − k·xc
  out.var_k = static_cast<double>(var_k);
  out.var_c = static_cast<double>(var_cc - 2 * lxc * cov + lxc * lxc * var_k);
  out.cov_kc = static_cast<double>(cov - lxc * var_k);
  out.chi2 = static_cast<double>(chi2);
  out.dof = static_cast<int>(n) - 2;
  return out;
}

std::vector<L> CentredX(LineRows d, double xc) {
  std::vector<L> x(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) x[i] = static_cast<L>(d.x[i]) - xc;
  return x;
}

}  // namespace

std::vector<double> LineSolution::Values(bool scaled) const {
  return {k, c, std::sqrt(scaled ? ScaledVarK() : var_k), std::sqrt(scaled ? ScaledVarC() : var_c)};
}

LineSolution OrdinaryLeastSquares(LineRows d) { return LeastSquares(d, false); }
LineSolution WeightedLeastSquares(LineRows d) { return LeastSquares(d, true); }

LineSolution YorkLine(LineRows d) {
  const std::size_t n = d.size();
  if (n < 3 || d.y.size() != n || d.u_x.size() != n || d.u_y.size() != n)
    throw std::invalid_argument("oracle: York's line needs >= 3 rows with all four columns");
  // X centred at a double near the middle: the subtraction is exact when both are within a
  // factor 2, and otherwise rounded to long double's 64 bits.
  const double xc = d.x[n / 2];
  const std::vector<L> x = CentredX(d, xc);
  std::vector<L> ux2(n), uy2(n), W(n), beta(n);
  for (std::size_t i = 0; i < n; ++i) {
    ux2[i] = static_cast<L>(d.u_x[i]) * d.u_x[i];
    uy2[i] = static_cast<L>(d.u_y[i]) * d.u_y[i];
  }
  L k = 0, xbar = 0, ybar = 0;
  {  // start: the OLS slope
    L sx = 0, sy = 0;
    for (std::size_t i = 0; i < n; ++i) sx += x[i], sy += d.y[i];
    const L mx = sx / n, my = sy / n;
    L sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (d.y[i] - my);
    k = sxy / sxx;
  }
  const auto means = [&] {
    L sw = 0, swx = 0, swy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      W[i] = 1 / (uy2[i] + k * k * ux2[i]);
      sw += W[i];
      swx += W[i] * x[i];
      swy += W[i] * d.y[i];
    }
    xbar = swx / sw;
    ybar = swy / sw;
    return sw;
  };
  L previous_step = INFINITY;
  for (int it = 0; it < 10000; ++it) {
    means();
    L num = 0, den = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const L U = x[i] - xbar, V = d.y[i] - ybar;
      beta[i] = W[i] * (U * uy2[i] + k * V * ux2[i]);
      num += W[i] * beta[i] * V;
      den += W[i] * beta[i] * U;
    }
    const L next = num / den, step = std::fabs(next - k);
    k = next;
    // Linear convergence down to the rounding floor of long double, where the step stops
    // shrinking.
    if (step == 0 || (step <= 1e-17L * std::fabs(k) && step >= previous_step)) break;
    previous_step = step;
  }
  const L sw = means();
  const L c = ybar - k * xbar;  // intercept in centred X
  // Errors (eq. 13): adjusted x_i = x̄ + β_i, their weighted mean ξ̄ and spread.
  L swxi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L U = x[i] - xbar, V = d.y[i] - ybar;
    beta[i] = W[i] * (U * uy2[i] + k * V * ux2[i]);
    swxi += W[i] * (xbar + beta[i]);
  }
  const L xi_bar = swxi / sw;
  L swu2 = 0, chi2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const L u = xbar + beta[i] - xi_bar;
    swu2 += W[i] * u * u;
    const L r = d.y[i] - c - k * x[i];
    chi2 += W[i] * r * r;
  }
  const L var_k = 1 / swu2, xi_bar_abs = xi_bar + xc;
  LineSolution s;
  s.k = static_cast<double>(k);
  s.c = static_cast<double>(c - k * xc);
  s.var_k = static_cast<double>(var_k);
  s.var_c = static_cast<double>(1 / sw + xi_bar_abs * xi_bar_abs * var_k);
  s.cov_kc = static_cast<double>(-xi_bar_abs * var_k);
  s.chi2 = static_cast<double>(chi2);
  s.dof = static_cast<int>(n) - 2;
  return s;
}

LineSolution HuberLine(LineRows d, double delta) {
  const std::size_t n = d.size();
  if (d.u_y.size() != n) throw std::invalid_argument("oracle: HuberLine needs u(Y)");
  const LineSolution wls = WeightedLeastSquares(d);
  const double xc = d.x[n / 2];
  std::vector<L> inv_sigma(n);
  for (std::size_t i = 0; i < n; ++i) inv_sigma[i] = 1 / static_cast<L>(d.u_y[i]);
  const std::vector<L> x = CentredX(d, xc);
  L k = wls.k, c = wls.c + static_cast<L>(wls.k) * xc;
  HuberNewton(d, x, inv_sigma, delta, k, c);
  return HuberSolution(d, x, inv_sigma, xc, delta, k, c);
}

LineSolution HuberLineMadScale(LineRows d, double delta) {
  const std::size_t n = d.size();
  const LineSolution ols = OrdinaryLeastSquares(d);
  const double xc = d.x[n / 2];
  const std::vector<L> x = CentredX(d, xc);
  // 1/Φ⁻¹(3/4): the MAD of Gaussian data estimates σ.
  const L mad_to_sigma = 1 / 0.674489750196081743202227014541L;
  std::vector<L> r(n);
  const auto scale = [&](L k, L c) {
    for (std::size_t i = 0; i < n; ++i) r[i] = std::fabs(d.y[i] - c - k * x[i]);
    const std::size_t mid = n / 2;
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(mid), r.end());
    L median = r[mid];
    if (n % 2 == 0) median = (median + *std::max_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(mid))) / 2;
    return mad_to_sigma * median;
  };
  L k = ols.k, c = ols.c + static_cast<L>(ols.k) * xc;
  L sigma = scale(k, c);
  std::vector<L> inv_sigma(n);
  L previous_step = INFINITY;
  for (int round = 0; round < 1000; ++round) {
    std::fill(inv_sigma.begin(), inv_sigma.end(), 1 / sigma);
    HuberNewton(d, x, inv_sigma, delta, k, c);
    const L next = scale(k, c), step = std::fabs(next - sigma);
    sigma = next;
    // The fixed-point iteration converges linearly, down to the rounding floor of long double
    // (where the step stops shrinking).
    if (step == 0 || (step <= 1e-16L * sigma && step >= previous_step)) break;
    previous_step = step;
  }
  std::fill(inv_sigma.begin(), inv_sigma.end(), 1 / sigma);
  HuberNewton(d, x, inv_sigma, delta, k, c);
  LineSolution s = HuberSolution(d, x, inv_sigma, xc, delta, k, c);
  s.sigma = static_cast<double>(sigma);
  return s;
}

}  // namespace uphill::oracle
