// GaussianStream (model/gaussian_stream.hpp) against its documented definition and against the
// normal distribution. Truth: the ziggurat tables recomputed here from the header's formula in
// 50-digit arithmetic (Boost.Multiprecision); the stream written out again plainly from that
// paragraph with Random123's own scalar Philox4x32; Boost.Math's normal CDF.
#include "model/gaussian_stream.hpp"

#include <gtest/gtest.h>

#include <Random123/philox.h>

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/special_functions/erf.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <cstring>
#include <vector>

namespace uphill::testing {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// kAuto too: it runs Philox with AVX-512F where the CPU has it (kAvx2 with AVX2 only).
std::vector<VectorKernel> Kernels() {
  std::vector<VectorKernel> k = {VectorKernel::kScalar, VectorKernel::kAuto};
  if (VectorKernelAvailable(VectorKernel::kAvx2)) k.push_back(VectorKernel::kAvx2);
  return k;
}

// The tables of gaussian_stream.hpp from their definition: N = 1024, f(x) = exp(−x²/2), R as
// given, V = R·f(R) + sqrt(π/2)·erfc(R/√2), x_0 = V/f(R), x_1 = R,
// x_{i+1} = sqrt(−2·ln(f(x_i) + V/x_i)), x_N = 0; f_i = f(double x_i); both rounded to double.
struct Tables {
  std::vector<double> x, f;
};

Tables RecomputedTables() {
  using Big = boost::multiprecision::cpp_bin_float_50;
  constexpr int n = 1024;
  const Big r = ziggurat::kR;  // the documented R is this double, exactly
  auto f = [](const Big& x) -> Big { return exp(-x * x / 2); };
  const Big v = r * f(r) + sqrt(boost::math::constants::pi<Big>() / 2) * boost::math::erfc(r / sqrt(Big(2)));
  std::vector<Big> x(n + 1);
  x[0] = v / f(r);
  x[1] = r;
  for (int i = 1; i < n - 1; ++i) x[i + 1] = sqrt(-2 * log(f(x[i]) + v / x[i]));
  x[n] = 0;
  Tables t;
  for (const Big& xi : x) {
    t.x.push_back(static_cast<double>(xi));
    t.f.push_back(static_cast<double>(f(Big(t.x.back()))));
  }
  return t;
}

const Tables& Reference() {
  static const Tables t = RecomputedTables();
  return t;
}

TEST(GaussianStream, TablesAreTheStatedFormulaRounded) {
  const Tables& t = Reference();
  ASSERT_EQ(ziggurat::kLayers, 1024);
  std::size_t x_diff = 0, f_diff = 0;
  for (int i = 0; i <= 1024; ++i) {
    x_diff += !SameBits(t.x[i], ziggurat::kX[i]);
    f_diff += !SameBits(t.f[i], ziggurat::kF[i]);
  }
  EXPECT_EQ(x_diff, 0u);
  EXPECT_EQ(f_diff, 0u);
  EXPECT_EQ(ziggurat::kX[1], ziggurat::kR);
  EXPECT_EQ(ziggurat::kF[1024], 1.0);
}

// Block j of a stream's main (lane3 = 0) or side (lane3 = 1) sequence, from r123::Philox4x32.
r123::Philox4x32::ctr_type Block(std::uint64_t seed, std::uint32_t id, std::uint32_t lane3, std::uint64_t j) {
  const r123::Philox4x32::ctr_type c = {{static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(j >> 32), id, lane3}};
  const r123::Philox4x32::key_type key = {{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}};
  return r123::Philox4x32()(c, key);
}
// Main word k (32 bits): output k mod 4 of block ⌊k/4⌋.
std::uint32_t MainWord(std::uint64_t seed, std::uint32_t id, std::uint64_t k) { return Block(seed, id, 0, k / 4).v[k % 4]; }
// Side word k (64 bits): c0 + 2^32·c1 (k even) or c2 + 2^32·c3 (k odd) of block ⌊k/2⌋.
std::uint64_t SideWord(std::uint64_t seed, std::uint32_t id, std::uint64_t k) {
  const r123::Philox4x32::ctr_type r = Block(seed, id, 1, k / 2);
  return k % 2 == 1 ? r.v[2] + (std::uint64_t{r.v[3]} << 32) : r.v[0] + (std::uint64_t{r.v[1]} << 32);
}

// The paragraph of gaussian_stream.hpp, one deviate at a time, with the recomputed tables.
struct PlainStream {
  std::uint64_t seed;
  std::uint32_t id;
  std::uint64_t main = 0, side = 0;
  int tails = 0, wedges = 0;

  double Next() {
    const Tables& t = Reference();
    std::uint32_t w = MainWord(seed, id, main++);
    for (;;) {
      const int i = static_cast<int>(w % 1024);
      const double sign = (w >> 10) % 2 == 1 ? -1.0 : 1.0;
      const std::uint32_t m = w >> 11;
      const double x = static_cast<double>(2 * m + 1) * std::ldexp(t.x[i], -22);
      if (x < t.x[i + 1]) return sign * x;
      if (i == 0) {
        ++tails;
        for (;;) {
          const double a = std::ldexp(static_cast<double>((SideWord(seed, id, side++) >> 11) + 1), -53);
          const double b = std::ldexp(static_cast<double>((SideWord(seed, id, side++) >> 11) + 1), -53);
          const double xi = -std::log(a) / t.x[1];
          const double eta = -std::log(b);
          if (eta + eta > xi * xi) return sign * (t.x[1] + xi);
        }
      }
      ++wedges;
      const double u = std::ldexp(static_cast<double>(SideWord(seed, id, side++) >> 11), -53);
      const double y = t.f[i] + u * (t.f[i + 1] - t.f[i]);
      if (y < std::exp(-(x * x) * 0.5)) return sign * x;
      w = static_cast<std::uint32_t>(SideWord(seed, id, side++) % (std::uint64_t{1} << 32));
    }
  }
};

TEST(GaussianStream, IsItsDocumentedDefinitionBitForBit) {
  const std::size_t n = 1'000'003;
  for (std::uint64_t seed : {1ull, 0x9E3779B97F4A7C15ull}) {
    for (std::uint32_t id : {0u, 7u}) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed << " id " << id);
      PlainStream plain{seed, id};
      std::vector<double> expected(n);
      for (double& z : expected) z = plain.Next();
      // The slow path was exercised (≈ 0.43 % of values; the tail ≈ 5e-5 of them per the layer).
      EXPECT_GT(plain.wedges, 2000);
      EXPECT_GT(plain.tails, 10);
      for (VectorKernel kernel : Kernels()) {
        SCOPED_TRACE(static_cast<int>(kernel));
        GaussianStream stream(seed, id), scaled(seed, id);
        std::vector<double> z(n), y(n);
        // Odd chunk sizes: the stream's state (main and side words) carries over between calls.
        std::size_t done = 0, chunk = 1;
        while (done < n) {
          const std::size_t m = std::min(chunk, n - done);
          stream.Fill(m, z.data() + done, kernel);
          scaled.FillScaled(m, 1.165, 0.002, y.data() + done, kernel);
          done += m;
          chunk = chunk * 7 % 2053 + 1;
        }
        std::size_t mismatches = 0, scaled_mismatches = 0;
        for (std::size_t i = 0; i < n; ++i) {
          mismatches += !SameBits(z[i], expected[i]);
          volatile double product = 0.002 * expected[i];  // one rounding, then the addition's
          scaled_mismatches += !SameBits(y[i], 1.165 + product);
        }
        EXPECT_EQ(mismatches, 0u);
        EXPECT_EQ(scaled_mismatches, 0u);
      }
    }
  }
}

// Kolmogorov–Smirnov against Boost.Math's normal CDF on 10^6 deviates of one fixed stream, the
// first six moments against the normal's, and the two-sided frequencies beyond 3 σ, 4 σ and R (the
// tail path) against their binomial expectations. False-alarm rates for a correct generator
// (i.e. were the seed random): KS sqrt(n)·D > 2.69 has probability 2·exp(−2·2.69²) ≈ 1e-6; each
// moment and frequency test at 5 standard errors ≈ 6e-7 (normal approximation; the sixth moment's
// heavy-tailed terms make its rate somewhat larger).
TEST(GaussianStream, IsStandardNormal) {
  const std::size_t n = 1'000'000;
  GaussianStream stream(20261123, 3);
  std::vector<double> z(n);
  stream.Fill(n, z.data());
  std::sort(z.begin(), z.end());
  const boost::math::normal normal;
  double d = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double p = boost::math::cdf(normal, z[i]);
    d = std::max({d, p - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - p});
  }
  EXPECT_LT(std::sqrt(static_cast<double>(n)) * d, 2.69);
  // The moments E z^p against the normal's (0, 1, 0, 3, 0, 15 for p = 1 … 6), each within 5 standard
  // errors sqrt((E z^2p − (E z^p)²)/n) (E z^2p = (2p − 1)!!: 1, 3, 15, 105, 945, 10395): the odd
  // ones test the symmetry (the sign bit), the even ones the layers' and the tail's weights.
  const double expected_moment[7] = {1, 0, 1, 0, 3, 0, 15};
  const double even_moment[13] = {1, 0, 1, 0, 3, 0, 15, 0, 105, 0, 945, 0, 10395};
  for (int p = 1; p <= 6; ++p) {
    SCOPED_TRACE(p);
    double sum = 0.0;
    for (double v : z) sum += std::pow(v, p);
    const double moment = sum / static_cast<double>(n);
    const double se = std::sqrt((even_moment[2 * p] - expected_moment[p] * expected_moment[p]) / static_cast<double>(n));
    EXPECT_LT(std::abs(moment - expected_moment[p]), 5 * se);
  }
  for (double limit : {3.0, 4.0, ziggurat::kR}) {
    SCOPED_TRACE(limit);
    const double p = 2 * boost::math::cdf(boost::math::complement(normal, limit));
    const auto below = std::lower_bound(z.begin(), z.end(), -limit) - z.begin();
    const auto above = z.end() - std::upper_bound(z.begin(), z.end(), limit);
    const double count = static_cast<double>(below + above);
    const double expected = p * static_cast<double>(n);
    EXPECT_LT(std::abs(count - expected), 5 * std::sqrt(expected * (1 - p)));
  }
}

// Philox's first published known-answer vector (Random123's kat_vectors: philox4x32 10 rounds,
// counter and key all ones): the generator this build links is the one documented.
TEST(GaussianStream, PhiloxKnownAnswer) {
  const r123::Philox4x32::ctr_type c = {{0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff}};
  const r123::Philox4x32::key_type key = {{0xffffffff, 0xffffffff}};
  const r123::Philox4x32::ctr_type r = r123::Philox4x32()(c, key);
  EXPECT_EQ(r.v[0], 0x408f276du);
  EXPECT_EQ(r.v[1], 0x41c83b0eu);
  EXPECT_EQ(r.v[2], 0xa20bc7c6u);
  EXPECT_EQ(r.v[3], 0x6d5451fdu);
}

}  // namespace
}  // namespace uphill::testing
