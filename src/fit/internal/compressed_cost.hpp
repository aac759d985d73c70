// Internal to the fit layer. CompressedLineCost: a ceres::CostFunction that hands Ceres the
// N residuals of a two-parameter (line) problem compressed to 3, so that large fits cost one pass
// over the rows per evaluation and no N-sized storage.
//
// What Ceres' Gauss-Newton / Levenberg-Marquardt iteration and ceres::Covariance use of a
// least-squares problem Σ r_i(θ)² are the cost, the gradient Jᵀr, the Gauss-Newton matrix JᵀJ and
// products J·δ through ‖Jδ‖² and rᵀJδ. All are fixed by the sums rᵀr, Jᵀr, JᵀJ, which
// RowSums() computes in one pass over the rows (the subclass's vectorised kernel). Evaluate
// returns 3 residuals z and a 3×2 Jacobian J_z with
//     J_zᵀJ_z = JᵀJ,   J_zᵀz = Jᵀr,   zᵀz = rᵀr:
//     J_z = [Lᵀ; 0] with JᵀJ = L·Lᵀ (Cholesky),  z = (L⁻¹Jᵀr, sqrt(rᵀr − ‖L⁻¹Jᵀr‖²)).
// J_z has the singular values of J, so Ceres' steps, its termination tests, the rank test and
// the (JᵀJ)⁻¹ of ceres::Covariance are those of the N-row problem, to rounding (tests compare
// with ceres::Covariance of the N-residual problem: ≤ 1e-13 relative). rᵀr − ‖L⁻¹Jᵀr‖² is the
// squared residual left after the Gauss-Newton step, ≥ 0 up to rounding (clamped at 0).
// When JᵀJ is not positive definite (rank-deficient design) J_z = diag(sqrt(λ))·Vᵀ from its
// eigen-decomposition, which ceres::Covariance then reports as rank deficient.
//
// The last two evaluations are memoised (θ compared bitwise): Ceres evaluates the cost at a
// candidate and then, when it accepts it, the Jacobian at the same point; the refinement and
// the covariance also revisit the final point. Not thread-safe (the fits run Ceres on one
// thread).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <array>
#include <limits>

namespace uphill::internal {

struct LineSums {
  double rr = 0.0;                                // Σ r_i²
  Eigen::Vector2d jtr = Eigen::Vector2d::Zero();  // Σ J_iᵀ r_i, the gradient of ½Σ r²
  Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();  // Σ J_iᵀ J_i
  // The exact Hessian of ½Σ r², JᵀJ + Σ r_i ∇²r_i, when the subclass provides it (else JᵀJ).
  Eigen::Matrix2d hessian = Eigen::Matrix2d::Zero();
};

class CompressedLineCost;

// Newton's method on ½Σ r² (the exact Hessian of LineSums; JᵀJ where it is not positive
// definite), repeated while the step shrinks; a step that raises the cost beyond rounding is
// undone. A step of norm ≤ unverified_below·‖θ‖ is taken without a further pass and ends the
// refinement: 4ε (the default) is the rounding level, where no check is needed; a caller that
// checks the gradient at the result anyway (e.g. in its pass for the per-row results) may trust a
// larger step, since Newton squares the error (a step of 1e-7 leaves ~1e-14 or less). The polish
// after Ceres, which stops on its cost test with parameters good to ~1e-9 (fit_options.hpp):
// from there one Newton step reaches the rounding level, where Gauss-Newton (RefineGaussNewton)
// gains only the factor by which it neglects the curvature of the residuals (~1e-2 per pass for
// York's fit). Returns the steps taken.
int RefineNewton(const CompressedLineCost& cost, double* theta,
                 double unverified_below = 4.0 * std::numeric_limits<double>::epsilon());


class CompressedLineCost : public ceres::CostFunction {
 public:
  CompressedLineCost();
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const final;
  // The sums at θ (memoised), or nullptr when they are not finite. passes(): row passes so far.
  // with_hessian: also LineSums::hessian (the exact one, when the subclass can; some more work
  // per row, so Ceres' evaluations go without).
  const LineSums* Sums(const double* theta, bool with_hessian = false) const;
  int passes() const { return passes_; }

 protected:
  // Stores sums computed elsewhere (e.g. by a pass that also writes per-row results) as the
  // evaluation at θ.
  void Remember(const double* theta, const LineSums& sums, bool has_hessian) const;
  // One pass over the rows at θ = (slope, intercept); false if a sum is not finite.
  // with_hessian false: leave sums->hessian = JᵀJ.
  virtual bool RowSums(const double* theta, bool with_hessian, LineSums* sums) const = 0;

 private:
  struct Memo {
    double theta[2] = {0.0, 0.0};
    bool valid = false, ok = false, has_hessian = false;
    LineSums sums;
  };
  mutable std::array<Memo, 2> memo_;
  mutable int next_ = 0;
  mutable int passes_ = 0;
};

}  // namespace uphill::internal
