// LineRowResults: the per-row results of a straight-line fit (OLS, WLS, York, robust), computed on
// demand from the fit and its data - the numbers the fit writes into FitReport::rows when
// FitOptions::keep_rows is set, bit for bit (both come from one function). For callers that
// stream the rows of a large fit (`uphill fit --xy --json`) instead of holding them: 10^7 rows
// would take 560 MB as RowResult.
//
// Per row i: residual Y_i − c − k·X_i (from the centred data, no cancellation), fitted =
// Y_i − residual, σ_i and the normalised residual residual/σ_i (see LineRowModel), the robust
// weight ρ'(s_i) (1 for the non-robust fits) and the outlier flag |normalised| > the fit's
// outlier threshold. Cost: a few flops per row (York: a square root and a division).
#pragma once

#include <cstddef>
#include <stdexcept>

#include "fit/fit_report.hpp"
#include "fit/line_data.hpp"

namespace uphill {

class LineRowResults {
 public:
  // `fit` must be a line fit of `data` (throws std::invalid_argument otherwise); both must
  // outlive this object.
  LineRowResults(const FitReport& fit, const LineData& data);
  std::size_t size() const { return data_->size(); }
  RowResult operator[](std::size_t i) const;

 private:
  const FitReport* fit_;
  const LineData* data_;
};

}  // namespace uphill
