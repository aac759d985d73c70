// NarrowAtan (src/model/internal/narrow_atan.hpp), the Monte Carlo's atan over a narrow interval,
// against long double atanl (glibc, 64-bit significand: its own error, ~2^-64 relative, is far
// below the double ulp measured here), over the intervals a Monte Carlo meets: the lab case's
// tanθ ≈ 0.2575, tan(α/2) ≈ 0.0193 and φ's argument, and wider and larger ones.
#include "internal/narrow_atan.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "model/vector_kernel.hpp"

namespace uphill::internal {
namespace {

// |y − atan(x)| in ulps of the double nearest atan(x).
double UlpError(double y, double x, double scale) {
  const long double exact = scale * std::atan(static_cast<long double>(x));
  const double nearest = static_cast<double>(exact);
  const double ulp = std::nextafter(std::abs(nearest), HUGE_VAL) - std::abs(nearest);
  return static_cast<double>(std::abs(static_cast<long double>(y) - exact) / ulp);
}

TEST(NarrowAtan, WithinAnUlpOverMonteCarloIntervals) {
  if (!CpuHasAvx2Fma()) GTEST_SKIP() << "Evaluate is AVX2 + FMA code";
  struct Case {
    double centre, relative_half_width, ulps;
  };
  // ±6 standard uncertainties of the lab case's arguments (≈ 0.4 %, 1.1 %): within 0.6 ulp (the
  // last addition's rounding dominates); wider intervals, where the correction term's own
  // rounding shows: within 1.1 ulp (measured: 0.52–0.56, 0.60–0.73, 1.03).
  for (const Case c : {Case{0.2575, 0.024, 0.6}, Case{0.0193, 0.066, 0.6}, Case{0.0187, 0.066, 0.6},
                       Case{3.0, 0.02, 0.6}, Case{0.2575, 0.2, 1.1}, Case{1.0, 0.05, 1.1},
                       Case{1e-3, 0.3, 1.1}}) {
    SCOPED_TRACE(::testing::Message() << "centre " << c.centre << " ± " << c.relative_half_width);
    const double lo = c.centre * (1 - c.relative_half_width), hi = c.centre * (1 + c.relative_half_width);
    const NarrowAtan f(c.centre);
    const int degree = f.DegreeFor(lo, hi);
    ASSERT_GT(degree, 0);
    EXPECT_LE(degree, NarrowAtan::kMaxDegree);
    const std::size_t n = 100003;  // odd: the padded tail too
    std::vector<double> x(n), y(n), y2(n);
    for (std::size_t j = 0; j < n; ++j) x[j] = lo + (hi - lo) * static_cast<double>(j) / static_cast<double>(n - 1);
    f.Evaluate(n, x.data(), 1.0, y.data(), degree);
    f.Evaluate(n, x.data(), 2.0, y2.data(), degree);
    double worst = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      worst = std::max(worst, UlpError(y[j], x[j], 1.0));
      EXPECT_EQ(y2[j], 2 * y[j]);  // the scale is exact
    }
    EXPECT_LE(worst, c.ulps);
  }
}

// The lab case's arguments need a short polynomial, the point of the class: degree ≤ 8.
TEST(NarrowAtan, LabCaseDegreesAreShort) {
  EXPECT_LE(NarrowAtan(0.2575).DegreeFor(0.2575 * 0.976, 0.2575 * 1.024), 8);
  EXPECT_LE(NarrowAtan(0.0193).DegreeFor(0.0193 * 0.934, 0.0193 * 1.066), 8);
}

// Where no polynomial of degree ≤ kMaxDegree is good to 2^-56, DegreeFor says 0 (the caller then
// falls back to libmvec): an interval reaching 0 or beyond, too wide, or not finite.
TEST(NarrowAtan, RefusesIntervalsItCannotServe) {
  const NarrowAtan f(0.25);
  EXPECT_EQ(f.DegreeFor(0.0, 0.5), 0);
  EXPECT_EQ(f.DegreeFor(-0.1, 0.3), 0);
  EXPECT_EQ(f.DegreeFor(0.01, 0.9), 0);
  EXPECT_EQ(f.DegreeFor(0.2, NAN), 0);
  EXPECT_EQ(f.DegreeFor(0.2, HUGE_VAL), 0);
  EXPECT_EQ(f.DegreeFor(0.3, 0.2), 0);
  EXPECT_GT(f.DegreeFor(0.25, 0.25), 0);  // a constant argument: degree 1 serves
}

}  // namespace
}  // namespace uphill::internal
