// A least-squares block handed to Ceres as few rows as it has unknowns, plus one.
//
// A block with m residuals r and Jacobian J (m × 5) enters Gauss–Newton and Levenberg–Marquardt
// only through JᵀJ, Jᵀr and |r|²; so does a robust loss's correction (Ceres's Corrector: a
// function of |r|², applied to J and r linearly) and Ceres's model of the cost change. The QR
// factor of the block's columns side by side, [J r] = Q·[R z; 0 ρ], gives 6 rows with the same
// three: r̃ = (z, ρ), J̃ = (R; 0). The tracker's outline fit hands each ray's ~100 residuals to
// Ceres that way (outline_fit.cpp), so that the solver's own work per ray is that of 6 rows.
//
// Accuracy: R is the Cholesky factor of the Gram matrix [J r]ᵀ[J r] after scaling its columns to
// unit norm (so that columns in metres against columns in pixels do not square into its
// condition): R̃ᵀR̃ matches [J r]ᵀ[J r] to a few units of rounding relative to its entries, and
// the least-squares step from (R, z) matches the full block's to about cond(scaled J)² × 1e-16.
// Where that Gram matrix is not positive definite (a column of zeros, or r in the span of J)
// Householder QR is used instead, accurate to rounding.
#pragma once

#include <Eigen/Core>
#include <cstddef>

namespace uphill::internal {

constexpr int kReducedUnknowns = 5;
using ReducedRows = Eigen::Matrix<double, kReducedUnknowns + 1, kReducedUnknowns + 1>;

// The upper triangular R of [J r] = Q·R: `jacobian` row-major (rows × 5), `residuals` (rows);
// rows below the first `rows` are zero when rows < 6. Columns 0–4 of R are J̃, column 5 is r̃.
ReducedRows ReduceRows(const double* jacobian, const double* residuals, std::size_t rows);

}  // namespace uphill::internal
