#include "fit/line_rows.hpp"

#include "internal/row_model.hpp"

namespace uphill {

LineRowResults::LineRowResults(const FitReport& fit, const LineData& data) : fit_(&fit), data_(&data) {
  if (!fit.row_model.valid || fit.n != data.size())
    throw std::invalid_argument("LineRowResults: not a line fit of these data");
}

RowResult LineRowResults::operator[](std::size_t i) const {
  const LineData& d = *data_;
  return internal::EvaluateRow(fit_->row_model, fit_->outlier_threshold, i, d.x[i], d.y[i],
                                   d.u_x.empty() ? 0.0 : d.u_x[i], d.u_y.empty() ? 0.0 : d.u_y[i]);
}

}  // namespace uphill
