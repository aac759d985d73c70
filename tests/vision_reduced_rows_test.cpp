// A least-squares block reduced to 6 rows for Ceres (src/vision/internal/reduced_rows.hpp).
//
// Truth: the block itself. The 6 rows must keep [J r]ᵀ[J r] (so JᵀJ, Jᵀr and |r|²), and the
// least-squares step they give must be the full block's, solved by Eigen's column-pivoting
// Householder QR of J (another algorithm than the reduction's Cholesky of the Gram matrix). The
// blocks are random, with columns scaled as the outline fit's are (metres against pixels).
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <random>

#include "internal/reduced_rows.hpp"

namespace uphill::internal {
namespace {

using Block = Eigen::Matrix<double, Eigen::Dynamic, kReducedUnknowns + 1>;

// [J r] of `rows` rows: J's columns scaled by (4e4, 4e4, 2e3, 2e3, 1), like ∂/∂(x, z) in px per
// metre, ∂/∂(smear) and ∂/∂(edge shift).
Block RandomBlock(int rows, unsigned seed) {
  std::mt19937 engine(seed);
  std::normal_distribution<double> normal;
  Block a(rows, kReducedUnknowns + 1);
  const double scale[] = {4e4, 4e4, 2e3, 2e3, 1, 1};
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j <= kReducedUnknowns; ++j) a(i, j) = scale[j] * normal(engine);
  return a;
}

ReducedRows Reduce(const Block& a) { return FactorGram(a.transpose() * a); }

// Largest relative difference between R's Gram matrix and the block's, entry by entry against
// the product of the columns' norms (the scale rounding acts on; the largest column's, for a
// column of zeros).
double GramError(const ReducedRows& r, const Block& a) {
  const Eigen::MatrixXd want = a.transpose() * a, got = r.transpose() * r;
  const double largest = want.diagonal().maxCoeff();
  double worst = 0;
  for (int j = 0; j <= kReducedUnknowns; ++j)
    for (int k = 0; k <= kReducedUnknowns; ++k) {
      const double scale = want(j, j) * want(k, k) > 0 ? std::sqrt(want(j, j) * want(k, k)) : largest;
      worst = std::max(worst, std::abs(got(j, k) - want(j, k)) / scale);
    }
  return worst;
}

TEST(ReducedRows, KeepTheGramMatrixAndTheLeastSquaresStep) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Block a = RandomBlock(96, seed);
    const ReducedRows r = Reduce(a);
    EXPECT_TRUE(r.isUpperTriangular(0.0));
    EXPECT_LT(GramError(r, a), 1e-14) << "seed " << seed;
    // The step: J·x ≈ r in least squares, from the 6 rows against the full block.
    const Eigen::Matrix<double, kReducedUnknowns, 1> reduced =
        r.topLeftCorner<kReducedUnknowns, kReducedUnknowns>().triangularView<Eigen::Upper>().solve(
            r.topRightCorner<kReducedUnknowns, 1>());
    const Eigen::VectorXd full = a.leftCols<kReducedUnknowns>().colPivHouseholderQr().solve(a.col(kReducedUnknowns));
    for (int j = 0; j < kReducedUnknowns; ++j) EXPECT_NEAR(reduced(j), full(j), 1e-12 * std::abs(full(j)) + 1e-18);
    EXPECT_NEAR(r.col(kReducedUnknowns).squaredNorm(), a.col(kReducedUnknowns).squaredNorm(),
                1e-13 * a.col(kReducedUnknowns).squaredNorm());
  }
}

// Where the Gram matrix is singular the reduction takes its symmetric square root: a ray whose
// colours could not be solved has a Jacobian of zeros, and a block may have fewer rows than 6.
TEST(ReducedRows, SingularAndShortBlocks) {
  Block zeros = RandomBlock(40, 7);
  zeros.col(2).setZero();
  EXPECT_LT(GramError(Reduce(zeros), zeros), 1e-14);
  Block in_span = RandomBlock(40, 8);
  in_span.col(kReducedUnknowns) = in_span.leftCols<kReducedUnknowns>() * Eigen::Matrix<double, 5, 1>(1e-4, 2e-4, 0.1, -0.1, 3);
  EXPECT_LT(GramError(Reduce(in_span), in_span), 1e-12);
  const Block short_block = RandomBlock(3, 9);
  EXPECT_LT(GramError(Reduce(short_block), short_block), 1e-12);
}

}  // namespace
}  // namespace uphill::internal
