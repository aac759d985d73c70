#include "reduced_rows.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace uphill::internal {

ReducedRows FactorGram(const ReducedRows& gram) {
  constexpr int kColumns = kReducedUnknowns + 1;
  // Columns scaled to unit norm (a column of zeros left as it is).
  Eigen::Matrix<double, kColumns, 1> scale = gram.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (int j = 0; j < kColumns; ++j)
    if (!(scale(j) > 0)) scale(j) = 1;
  const Eigen::Matrix<double, kColumns, 1> inverse = scale.cwiseInverse();
  const ReducedRows scaled = inverse.asDiagonal() * gram * inverse.asDiagonal();
  const Eigen::LLT<ReducedRows> llt(scaled);
  if (llt.info() == Eigen::Success) {
    const ReducedRows upper = llt.matrixU();
    return upper * scale.asDiagonal();
  }
  const Eigen::SelfAdjointEigenSolver<ReducedRows> eigen(scaled);
  return eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * eigen.eigenvectors().transpose() *
         scale.asDiagonal();
}

}  // namespace uphill::internal
