// A least-squares block handed to Ceres as few rows as it has unknowns, plus one.
//
// A block with m residuals r and Jacobian J (m × 5) enters Gauss–Newton and Levenberg–Marquardt
// only through JᵀJ, Jᵀr and |r|²; so does a robust loss's correction (Ceres's Corrector: a
// function of |r|², applied to J and r linearly) and Ceres's model of the cost change. The QR
// factor of the block's columns side by side, [J r] = Q·[R z; 0 ρ], gives 6 rows with the same
// three: r̃ = (z, ρ), J̃ = (R; 0). The tracker's outline fit hands each ray's ~100 residuals to
// Ceres that way (outline_fit.cpp, which sums the Gram matrix over the samples without forming
// J), so that the solver's own work per ray is that of 6 rows.
//
// Accuracy: R is the Cholesky factor of the Gram matrix [J r]ᵀ[J r] after scaling its columns to
// unit norm (so that columns in metres against columns in pixels do not square into its
// condition): RᵀR matches the Gram matrix to a few units of rounding relative to its entries, and
// the least-squares step from (R, z) matches the full block's to about cond(scaled J)² × 1e-16.
// Where the Gram matrix is not positive definite (a column of zeros, or r in the span of J) R is
// its symmetric square root instead (not triangular; RᵀR = the Gram matrix, its negative
// rounding-level eigenvalues taken as 0).
#pragma once

#include <Eigen/Core>
#include <cstddef>

namespace uphill::internal {

constexpr int kReducedUnknowns = 5;
using ReducedRows = Eigen::Matrix<double, kReducedUnknowns + 1, kReducedUnknowns + 1>;

// R with RᵀR = gram, gram the Gram matrix [J r]ᵀ[J r] of a block (J: 5 columns, r: the last).
// Columns 0–4 of R are J̃, column 5 is r̃.
ReducedRows FactorGram(const ReducedRows& gram);

}  // namespace uphill::internal
