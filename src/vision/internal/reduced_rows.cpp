#include "reduced_rows.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>

namespace uphill::internal {

ReducedRows ReduceRows(const double* jacobian, const double* residuals, std::size_t rows) {
  constexpr int kUnknowns = kReducedUnknowns, kColumns = kReducedUnknowns + 1;
  // The Gram matrix's lower triangle, accumulated by hand: Eigen's rank update does not unroll
  // at this size, and this loop is most of the reduction's cost.
  double lower[kColumns][kColumns] = {};
  for (std::size_t i = 0; i < rows; ++i) {
    double row[kColumns];
    std::copy(jacobian + i * kUnknowns, jacobian + (i + 1) * kUnknowns, row);
    row[kUnknowns] = residuals[i];
    for (int j = 0; j < kColumns; ++j)
      for (int k = 0; k <= j; ++k) lower[j][k] += row[j] * row[k];
  }
  ReducedRows gram;
  for (int j = 0; j < kColumns; ++j)
    for (int k = 0; k <= j; ++k) gram(j, k) = gram(k, j) = lower[j][k];
  const Eigen::Matrix<double, kColumns, 1> scale = gram.diagonal().cwiseSqrt();
  if (scale.minCoeff() > 0) {
    const Eigen::Matrix<double, kColumns, 1> inverse = scale.cwiseInverse();
    const Eigen::LLT<ReducedRows> llt(inverse.asDiagonal() * gram * inverse.asDiagonal());
    if (llt.info() == Eigen::Success) {
      const ReducedRows upper = llt.matrixU();
      return upper * scale.asDiagonal();
    }
  }
  Eigen::Matrix<double, Eigen::Dynamic, kColumns> a(static_cast<Eigen::Index>(rows), kColumns);
  for (std::size_t i = 0; i < rows; ++i) {
    for (int j = 0; j < kUnknowns; ++j) a(static_cast<Eigen::Index>(i), j) = jacobian[i * kUnknowns + j];
    a(static_cast<Eigen::Index>(i), kUnknowns) = residuals[i];
  }
  const Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, kColumns>> qr(a);
  ReducedRows upper = ReducedRows::Zero();
  const Eigen::Index top = std::min<Eigen::Index>(static_cast<Eigen::Index>(rows), kColumns);
  upper.topRows(top) = qr.matrixQR().topRows(top).triangularView<Eigen::Upper>();
  return upper;
}

}  // namespace uphill::internal
