// Internal to the fit layer: one row's results from a LineRowModel (fit_report.hpp), shared by
// the line fits' last pass and LineRowResults, so that stored and on-demand rows agree bit for
// bit. Inline: the fits call it in their row loops.
#pragma once

#include <cmath>
#include <cstddef>

#include "fit/fit_report.hpp"

namespace uphill::internal {

// The robust weight ρ'(s), s = z², of the model's loss at normalised residual z.
inline double RobustWeight(const LineRowModel& m, double z) {
  switch (m.weight) {
    case LineRowModel::Weight::kOne:
      return 1.0;
    case LineRowModel::Weight::kHuber: {
      const double a = std::abs(z);
      return a <= m.loss_scale ? 1.0 : m.loss_scale / a;
    }
    case LineRowModel::Weight::kCauchy:
      return 1.0 / (1.0 + (z * z) / (m.loss_scale * m.loss_scale));
  }
  return 1.0;
}

// Row i of the data (x, y, u(X), u(Y); the u's unused where the model does not need them).
inline RowResult EvaluateRow(const LineRowModel& m, double outlier_threshold, std::size_t i, double x,
                             double y, double ux, double uy) {
  const double xs = (x - m.x0) * m.inv_sx;  // exact scaling: inv_sx is a power of two
  const double e = (y - m.y0) * m.inv_sy - m.c - m.k * xs;
  RowResult row;
  row.row = i;
  row.residual = m.sy * e;  // exact: sy is a power of two
  row.fitted = y - row.residual;
  switch (m.sigma) {
    case LineRowModel::Sigma::kCommon:
      row.sigma = m.sigma_common;
      row.normalised = row.sigma > 0.0 ? row.residual / row.sigma : 0.0;
      break;
    case LineRowModel::Sigma::kUy:
      row.sigma = uy;
      row.normalised = e / (uy * m.inv_sy);
      break;
    case LineRowModel::Sigma::kYork: {
      const double uxs = ux * m.inv_sx, uys = uy * m.inv_sy;
      const double var = uys * uys + m.k * m.k * (uxs * uxs);
      const double root_w = std::sqrt(1.0 / var);
      row.sigma = m.sy * (var * root_w);  // sqrt(var) to an ulp or two, without a second division
      row.normalised = e * root_w;
      break;
    }
  }
  row.weight = RobustWeight(m, row.normalised);
  row.outlier = std::abs(row.normalised) > outlier_threshold;
  return row;
}

}  // namespace uphill::internal
