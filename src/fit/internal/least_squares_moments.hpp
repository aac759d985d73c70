// Internal to the fit layer: the least-squares criterion of a straight line from the weighted
// moments of the data, for the linear fits (least_squares_line.cpp) and the robust fit's start.
//
// In standardised coordinates (x, y; σ_s = u(Y)/sy, or 1), θ = (k, c), the criterion Σ r_i²,
// r_i = w_i^½·(y_i − c − k·x_i), w_i = 1/σ_s,i², is quadratic in θ: its cost, gradient and
// Gauss-Newton matrix at any θ follow from six weighted moments S = Σ w (1, x, y, x², x·y, y²),
// taken in one vectorised pass (sums per chunk in vector lanes, chunks added in long double).
// LeastSquaresCost hands Ceres the N residuals compressed to 3 (compressed_cost.hpp) without a
// further pass over the rows, however many iterations it takes.
#pragma once

#include "compressed_cost.hpp"
#include "line_problem.hpp"

namespace uphill::internal {

struct LineMoments {
  double w = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
};

// weighted: w = 1/(u(Y)/sy)² (the view's u(Y)); else w = 1.
LineMoments TakeMoments(const StandardisedView& view, bool weighted);

class LeastSquaresCost final : public CompressedLineCost {
 public:
  explicit LeastSquaresCost(const LineMoments& m) : m_(m) {}

 private:
  // J_i = −w^½(x, 1): JᵀJ, Jᵀr and rᵀr from the moments. rᵀr is a difference of moments (it
  // cancels when the line fits closely): it only steers Ceres' cost tests - χ² comes from the
  // rows themselves.
  bool RowSums(const double* theta, bool with_hessian, LineSums* sums) const override;
  LineMoments m_;
};

}  // namespace uphill::internal
