#include "bench/synthetic_data.hpp"

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_real_distribution.hpp>

namespace uphill::bench {

LineData StraightLine(std::size_t n, std::uint64_t seed, double t0, double spread, double ux_scale) {
  boost::random::mt19937_64 engine(seed);
  boost::random::uniform_real_distribution<double> unit(0.0, 1.0);
  boost::random::normal_distribution<double> normal;
  const double k = 2.0, c = 1.0;
  LineData d;
  d.x.resize(n);
  d.y.resize(n);
  d.u_x.resize(n);
  d.u_y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0 + spread * unit(engine);
    d.u_x[i] = ux_scale * (0.05 + 0.15 * unit(engine));
    d.u_y[i] = ux_scale * (0.1 + 0.3 * unit(engine));
    d.x[i] = t + d.u_x[i] * normal(engine);
    d.y[i] = c + k * (t - t0) + d.u_y[i] * normal(engine);
  }
  return d;
}

ApparatusSettings RandomApparatusSettings(std::size_t n, std::uint64_t seed) {
  boost::random::mt19937_64 engine(seed);
  boost::random::uniform_real_distribution<double> uL(0.5, 2.0), uH(0.05, 0.5), uD(0.02, 0.25);
  ApparatusSettings s;
  s.L.resize(n);
  s.H.resize(n);
  s.D.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.L[i] = uL(engine);
    s.H[i] = uH(engine);
    s.D[i] = uD(engine);
  }
  return s;
}

}  // namespace uphill::bench
