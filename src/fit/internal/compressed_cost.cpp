#include "compressed_cost.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace uphill::internal {

CompressedLineCost::CompressedLineCost() {
  set_num_residuals(3);
  mutable_parameter_block_sizes()->push_back(2);
}

const LineSums* CompressedLineCost::Sums(const double* theta, bool with_hessian) const {
  for (const Memo& m : memo_)
    if (m.valid && (m.has_hessian || !with_hessian) &&
        std::memcmp(m.theta, theta, sizeof(m.theta)) == 0)
      return m.ok ? &m.sums : nullptr;
  Memo& m = memo_[static_cast<std::size_t>(next_)];
  next_ = 1 - next_;
  m.theta[0] = theta[0];
  m.theta[1] = theta[1];
  m.sums = LineSums{};
  ++passes_;
  m.has_hessian = with_hessian;
  m.ok = RowSums(theta, with_hessian, &m.sums) && std::isfinite(m.sums.rr) && m.sums.jtr.allFinite() &&
         m.sums.jtj.allFinite() && m.sums.hessian.allFinite();
  m.valid = true;
  return m.ok ? &m.sums : nullptr;
}

void CompressedLineCost::Remember(const double* theta, const LineSums& sums,
                                  bool has_hessian) const {
  Memo& m = memo_[static_cast<std::size_t>(next_)];
  next_ = 1 - next_;
  m.theta[0] = theta[0];
  m.theta[1] = theta[1];
  m.sums = sums;
  m.has_hessian = has_hessian;
  m.ok = std::isfinite(sums.rr) && sums.jtr.allFinite() && sums.jtj.allFinite() &&
         sums.hessian.allFinite();
  m.valid = true;
}

bool CompressedLineCost::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const LineSums* s = Sums(parameters[0]);
  if (!s) return false;
  // J_z = [T; 0] with TᵀT = JᵀJ; z = (a, b) with Tᵀa = Jᵀr, ‖a‖² + b² = rᵀr.
  Eigen::Matrix2d t;
  Eigen::Vector2d a;
  const Eigen::LLT<Eigen::Matrix2d> llt(s->jtj);
  if (llt.info() == Eigen::Success) {
    t = llt.matrixU();  // JᵀJ = UᵀU
    a = llt.matrixL().solve(s->jtr);
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(s->jtj);
    const Eigen::Vector2d root = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    t = root.asDiagonal() * eigen.eigenvectors().transpose();
    const Eigen::Vector2d projected = eigen.eigenvectors().transpose() * s->jtr;
    for (int i = 0; i < 2; ++i) a(i) = root(i) > 0.0 ? projected(i) / root(i) : 0.0;
  }
  residuals[0] = a(0);
  residuals[1] = a(1);
  residuals[2] = std::sqrt(std::max(s->rr - a.squaredNorm(), 0.0));
  if (jacobians && jacobians[0]) {
    double* j = jacobians[0];  // row-major 3×2
    j[0] = t(0, 0);
    j[1] = t(0, 1);
    j[2] = t(1, 0);
    j[3] = t(1, 1);
    j[4] = 0.0;
    j[5] = 0.0;
  }
  return true;
}

}  // namespace uphill::internal

namespace uphill::internal {

int RefineNewton(const CompressedLineCost& cost, double* theta, double unverified_below) {
  Eigen::Map<Eigen::Vector2d> t(theta);
  double previous_norm = std::numeric_limits<double>::infinity();
  int steps = 0;
  const LineSums* here = cost.Sums(theta, true);
  for (int iteration = 0; here && iteration < 50; ++iteration) {
    Eigen::LDLT<Eigen::Matrix2d> factor(here->hessian);
    if (!(factor.info() == Eigen::Success && (factor.vectorD().array() > 0.0).all()))
      factor.compute(here->jtj);
    const Eigen::Vector2d start = t, step = factor.solve(-here->jtr);
    const double norm = step.norm();
    if (!step.allFinite() || norm == 0.0 || !(norm < previous_norm)) break;  // rounding floor
    t = start + step;
    if (norm <= unverified_below * start.norm()) {
      ++steps;  // at the rounding level (or checked by the caller): take it and stop
      break;
    }
    const double cost_here = here->rr;
    const LineSums* there = cost.Sums(theta, true);
    if (!there || !(there->rr <= cost_here * (1.0 + 1e-12) + std::numeric_limits<double>::min())) {
      t = start;  // not a descent beyond rounding: keep the previous point
      break;
    }
    here = there;
    ++steps;
    previous_norm = norm;
  }
  return steps;
}

}  // namespace uphill::internal
