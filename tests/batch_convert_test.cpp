// The batch kernels (model/batch_convert.hpp) against the scalar model: kScalar bit for bit,
// kAvx2 within a few ulp; both against the 60-digit references.
#include "model/batch_convert.hpp"

#include <gtest/gtest.h>

#include <boost/random/mersenne_twister.hpp>

#include <boost/random/uniform_real_distribution.hpp>
#include <cmath>
#include <cstring>
#include <vector>

#include "model/double_cone_on_line_rails.hpp"
#include "model/spheroid_on_line_rails.hpp"
#include "model/spheroid_on_rods.hpp"
#include "reference_cases.hpp"

namespace uphill::testing {
namespace {

constexpr double kUlp = 1.1102230246251565e-16;  // 2^-53, half an ulp of 1

std::vector<VectorKernel> Kernels() {
  std::vector<VectorKernel> k = {VectorKernel::kScalar};
  if (VectorKernelAvailable(VectorKernel::kAvx2)) k.push_back(VectorKernel::kAvx2);
  return k;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Relative agreement: exact for kScalar, within `ulps` (of 2^-53) for kAvx2.
void ExpectClose(VectorKernel kernel, double actual, double model, double ulps, const char* what,
                 std::size_t i) {
  if (kernel == VectorKernel::kScalar) {
    EXPECT_TRUE(SameBits(actual, model)) << what << "[" << i << "] " << actual << " vs " << model;
  } else {
    EXPECT_NEAR(actual, model, ulps * kUlp * std::abs(model)) << what << "[" << i << "]";
  }
}

// Random configurations around the apparatus' range, with some extreme ones mixed in.
struct Configurations {
  std::vector<double> L, H, D, a, b, r, theta, alpha;
};

Configurations Random(std::size_t n, std::uint64_t seed) {
  boost::random::mt19937_64 engine(seed);
  auto uniform = [&](double lo, double hi) {
    return boost::random::uniform_real_distribution<double>(lo, hi)(engine);
  };
  Configurations c;
  for (std::size_t i = 0; i < n; ++i) {
    c.L.push_back(uniform(0.3, 3.0));
    c.H.push_back(i % 17 == 0 ? 0.0 : uniform(1e-6, 1.0));
    c.D.push_back(uniform(1e-4, 1.0));
    c.a.push_back(uniform(0.002, 0.05));
    c.b.push_back(uniform(0.002, 0.08));
    c.r.push_back(uniform(1e-4, 0.01));
    c.theta.push_back(i % 13 == 0 ? 0.0 : uniform(1e-6, 1.5));
    c.alpha.push_back(uniform(1e-4, 3.1));
  }
  return c;
}

TEST(BatchConvert, RailsFromApparatusMatchModel) {
  const std::size_t n = 1003;  // not a multiple of 4: the tail goes through the padded path
  const Configurations c = Random(n, 1);
  for (LConvention convention : {LConvention::kHorizontal, LConvention::kAlongRail}) {
    std::vector<double> L = c.L;
    if (convention == LConvention::kAlongRail)  // along a rail L must exceed hypot(H, D/2)
      for (std::size_t i = 0; i < n; ++i) L[i] = std::hypot(c.H[i], c.D[i] / 2) * (1.0 + c.L[i]);
    for (VectorKernel kernel : Kernels()) {
      SCOPED_TRACE(VectorKernelName(kernel));
      std::vector<double> theta(n), alpha(n), phi(n), B(n), T(n);
      RailsFromApparatusBatch(n, L.data(), c.H.data(), c.D.data(), convention,
                              {theta.data(), alpha.data(), phi.data(), B.data(), T.data()}, kernel);
      for (std::size_t i = 0; i < n; ++i) {
        const Rails rails = Rails::FromApparatus(L[i], c.H[i], c.D[i], convention);
        // The slopes: the same divisions; along a rail sqrt(fma) stands in for hypot.
        const double slope_ulps = convention == LConvention::kHorizontal ? 0 : 64;
        // atan (libmvec, ≤ 4 ulp) of a ratio rounded once, against libm's atan2.
        ExpectClose(kernel, theta[i], rails.theta, 12 + slope_ulps, "theta", i);
        ExpectClose(kernel, alpha[i], rails.alpha, 12 + slope_ulps, "alpha", i);
        ExpectClose(kernel, phi[i], rails.HalfAngleBetweenRails(), 16 + slope_ulps, "phi", i);
        ExpectClose(kernel, B[i], rails.tan_theta, slope_ulps, "tan_theta", i);
        ExpectClose(kernel, T[i], rails.tan_half_alpha, slope_ulps, "tan_half_alpha", i);
      }
    }
  }
}

TEST(BatchConvert, RailsFromAnglesMatchModel) {
  const std::size_t n = 1001;
  const Configurations c = Random(n, 2);
  for (VectorKernel kernel : Kernels()) {
    SCOPED_TRACE(VectorKernelName(kernel));
    std::vector<double> theta(n), alpha(n), phi(n), B(n), T(n);
    RailsFromAnglesBatch(n, c.theta.data(), c.alpha.data(),
                         {theta.data(), alpha.data(), phi.data(), B.data(), T.data()}, kernel);
    for (std::size_t i = 0; i < n; ++i) {
      const Rails rails = Rails::FromAngles(c.theta[i], c.alpha[i]);
      EXPECT_TRUE(SameBits(theta[i], c.theta[i]));
      EXPECT_TRUE(SameBits(alpha[i], c.alpha[i]));
      ExpectClose(kernel, B[i], rails.tan_theta, 8, "tan_theta", i);
      ExpectClose(kernel, T[i], rails.tan_half_alpha, 8, "tan_half_alpha", i);
      ExpectClose(kernel, phi[i], rails.HalfAngleBetweenRails(), 24, "phi", i);
    }
  }
}

TEST(BatchConvert, BodiesMatchModel) {
  const std::size_t n = 999;
  const Configurations c = Random(n, 3);
  std::vector<double> B(n), T(n);
  for (std::size_t i = 0; i < n; ++i) {
    B[i] = std::tan(c.theta[i]);
    T[i] = std::tan(c.alpha[i] / 2);
  }
  for (VectorKernel kernel : Kernels()) {
    SCOPED_TRACE(VectorKernelName(kernel));
    std::vector<double> x_eq(n), x_max(n), x_eq_r(n), x_max_r(n), x_fall(n), theta0(n), q(n);
    SpheroidBatch(n, c.a.data(), c.b.data(), nullptr, B.data(), T.data(), x_eq.data(),
                  x_max.data(), kernel);
    SpheroidBatch(n, c.a.data(), c.b.data(), c.r.data(), B.data(), T.data(), x_eq_r.data(),
                  x_max_r.data(), kernel);
    DoubleConeBatch(n, c.a.data(), c.b.data(), B.data(), T.data(), x_fall.data(), theta0.data(),
                    q.data(), kernel);
    for (std::size_t i = 0; i < n; ++i) {
      const SpheroidOnLineRails<double> line(c.a[i], c.b[i], B[i], T[i]);
      ExpectClose(kernel, x_eq[i], line.x_eq(), 8, "x_eq", i);
      ExpectClose(kernel, x_max[i], line.x_max(), 8, "x_max", i);
      const SpheroidOnRods rods(c.a[i], c.b[i], B[i], T[i], c.r[i]);
      ExpectClose(kernel, x_eq_r[i], rods.x_eq(), 8, "x_eq rods", i);
      ExpectClose(kernel, x_max_r[i], rods.x_max(), 8, "x_max rods", i);
      const DoubleConeOnLineRails<double> cone(c.a[i], c.b[i], B[i], T[i]);
      ExpectClose(kernel, x_fall[i], cone.x_fall(), 0, "x_fall", i);
      ExpectClose(kernel, theta0[i], cone.theta0(), 8, "theta0", i);
      // Q = (1 + B²) − (kT)²: kAvx2 rounds once less; compare absolutely (Q is O(1) or a
      // cancellation, which the sign test Q > 0 tolerates).
      if (kernel == VectorKernel::kScalar) {
        EXPECT_TRUE(SameBits(q[i], cone.Q()));
      } else {
        EXPECT_NEAR(q[i], cone.Q(), 8 * kUlp * (1 + B[i] * B[i] + cone.s()));
      }
    }
  }
}

TEST(BatchConvert, ResultDoesNotDependOnPositionOrBatchSize) {
  const Configurations c = Random(64, 4);
  for (VectorKernel kernel : Kernels()) {
    std::vector<double> full(64);
    ConvertApparatusBatch(64, c.L.data(), c.H.data(), c.D.data(), 0.015875, 0.0254, nullptr,
                          nullptr, full.data(), kernel);
    for (std::size_t start : {0, 1, 5, 30, 61, 63}) {
      for (std::size_t len = 1; start + len <= 64 && len <= 7; ++len) {
        std::vector<double> part(len);
        ConvertApparatusBatch(len, c.L.data() + start, c.H.data() + start, c.D.data() + start,
                              0.015875, 0.0254, nullptr, nullptr, part.data(), kernel);
        for (std::size_t k = 0; k < len; ++k)
          EXPECT_TRUE(SameBits(part[k], full[start + k])) << start << "+" << k;
      }
    }
  }
}

TEST(BatchConvert, FusedConversionAgreesWithTheStages) {
  const std::size_t n = 1503;  // several blocks of the scalar path, an odd tail
  const Configurations c = Random(n, 5);
  for (VectorKernel kernel : Kernels()) {
    std::vector<double> theta(n), alpha(n), x_eq(n), t2(n), a2(n), B(n), T(n), x2(n);
    ConvertApparatusBatch(n, c.L.data(), c.H.data(), c.D.data(), 0.015875, 0.0254, theta.data(),
                          alpha.data(), x_eq.data(), kernel);
    RailsFromApparatusBatch(n, c.L.data(), c.H.data(), c.D.data(), LConvention::kHorizontal,
                            {t2.data(), a2.data(), nullptr, B.data(), T.data()}, kernel);
    const std::vector<double> a(n, 0.015875), b(n, 0.0254);
    SpheroidBatch(n, a.data(), b.data(), nullptr, B.data(), T.data(), x2.data(), nullptr, kernel);
    // kScalar runs the stages themselves; kAvx2 has its own arrangement with fewer divisions.
    for (std::size_t i = 0; i < n; ++i) {
      ExpectClose(kernel, theta[i], t2[i], 12, "theta", i);
      ExpectClose(kernel, alpha[i], a2[i], 12, "alpha", i);
      ExpectClose(kernel, x_eq[i], x2[i], 12, "x_eq", i);
    }
  }
}

// The apparatus cases and the FIG. 5/6 sweeps of physics_reference.json, through the fused
// kernel (the path `uphill bench convert` times), within the reference file's tolerance.
TEST(BatchConvert, ReferenceCases) {
  using nlohmann::json;
  for (VectorKernel kernel : Kernels()) {
    SCOPED_TRACE(VectorKernelName(kernel));
    int checked = 0;
    for (const json& c : testing::ReferenceFile().at("cases")) {
      const bool rods = c.contains("rod_radius") && c.at("rod_radius").is_number() &&
                        c.at("rod_radius").get<double>() > 0;
      if (c.at("body").at("type") != "spheroid" || rods) continue;
      const double a = c.at("body").at("a"), b = c.at("body").at("b");
      std::vector<std::pair<std::array<double, 3>, const json*>> rows;
      if (c.at("rails").contains("apparatus")) {
        const json& app = c.at("rails").at("apparatus");
        rows.push_back({{app.at("L"), app.at("H"), app.at("D")}, &c.at("outputs")});
      } else if (c.at("rails").contains("sweep")) {
        // Angles as L = 1, H = tanθ, D = 2·tan(α/2): one more rounding in each slope.
        for (const json& row : c.at("outputs").at("sweep"))
          rows.push_back({{1.0, std::tan(row.at("theta").get<double>()),
                           2 * std::tan(row.at("alpha").get<double>() / 2)},
                          &row});
      }
      for (const auto& [in, out] : rows) {
        double theta, alpha, x_eq;
        ConvertApparatusBatch(1, &in[0], &in[1], &in[2], a, b, &theta, &alpha, &x_eq, kernel);
        const double cond = c.contains("cond") && c.at("cond").contains("x_eq") &&
                                    !c.at("cond").at("x_eq").is_null()
                                ? testing::Cond(c.at("cond").at("x_eq"))
                                : 10.0;
        EXPECT_REF(theta, out->at("theta"), 10.0);
        EXPECT_REF(alpha, out->at("alpha"), 10.0);
        EXPECT_REF(x_eq, out->at("x_eq"), cond);
        ++checked;
      }
    }
    EXPECT_GE(checked, 18);  // 4 lab cases and the sweeps' rows
  }
}

TEST(VectorKernelName, NamesTheChoice) {
  EXPECT_STREQ(VectorKernelName(VectorKernel::kScalar), "scalar (libm)");
  EXPECT_STREQ(VectorKernelName(VectorKernel::kAvx2), "avx2+fma (libmvec)");
  EXPECT_STREQ(VectorKernelName(VectorKernel::kAuto),
               VectorKernelName(VectorKernelAvailable(VectorKernel::kAvx2) ? VectorKernel::kAvx2
                                                                        : VectorKernel::kScalar));
}

}  // namespace
}  // namespace uphill::testing
