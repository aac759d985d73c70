// The benchmarks' synthetic data, seeded (boost::random, the same numbers on every platform).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fit/line_data.hpp"

namespace uphill::bench {

// Y = 1 + 2·(t − t0) + u(Y)·n₁, X = t + u(X)·n₂: the true t uniform on [t0, t0 + spread], u(X) ~
// ux_scale·U(0.05, 0.2) and u(Y) ~ ux_scale·U(0.1, 0.4) varying per row (so that the weighted fits
// differ from OLS), n₁, n₂ standard normal.
LineData StraightLine(std::size_t n, std::uint64_t seed, double t0, double spread, double ux_scale);

// n apparatus settings over its range, in metres: L ~ U(0.5, 2), H ~ U(0.05, 0.5), D ~ U(0.02, 0.25).
struct ApparatusSettings {
  std::vector<double> L, H, D;
};
ApparatusSettings RandomApparatusSettings(std::size_t n, std::uint64_t seed);

}  // namespace uphill::bench
