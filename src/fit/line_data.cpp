#include "fit/line_data.hpp"

#include <cmath>

#include "internal/line_problem.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {


std::string At(const std::string& column, std::size_t i) {
  return column + "[" + std::to_string(i) + "]";
}

// Squares, products and inverse squares of the data must stay finite and normal in binary64
// (weights are 1/u², York's use u² + k²·u(X)²): beyond these bounds Ceres' residuals overflow.
constexpr double kLargest = 1e100, kSmallestUncertainty = 1e-100;

// Whether every |v_i| ≤ bound (false for NaN and ±inf): a branch-free pass the compiler
// vectorises, so that valid data - the common case - costs one streaming read; the loops that
// name the offending row run only when it fails.
bool AllWithin(const std::vector<double>& v, double bound) {
  bool ok = true;
  for (double vi : v) ok &= std::abs(vi) <= bound;
  return ok;
}

// Likewise: every u_i in [lo, hi], or 0 when zero_allowed.
bool AllUncertaintiesWithin(const std::vector<double>& u, double lo, double hi, bool zero_allowed) {
  bool ok = true;
  for (double ui : u) ok &= (ui >= lo && ui <= hi) || (zero_allowed && ui == 0.0);
  return ok;
}

void RequireFinite(const std::vector<double>& v, const std::string& column) {
  if (AllWithin(v, kLargest)) return;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]))
      throw InputError(At(column, i), "must be finite (got " + ExactText(v[i]) + ")");
    if (std::abs(v[i]) > kLargest)
      throw InputError(At(column, i), "must be at most 1e100 in magnitude (got " + ExactText(v[i]) +
                                          "): its square would overflow a double");
  }
}

// The column must be present with one value per row, each finite and > 0 (or ≥ 0).
void RequireUncertainties(const std::vector<double>& u, std::size_t n, const std::string& column,
                          const std::string& method, bool zero_allowed) {
  if (u.empty())
    throw InputError(column, method + " needs an uncertainty for every row (none given)");
  if (u.size() != n)
    throw InputError(column, "must have one value per row (" + std::to_string(n) + " rows, got " +
                                 std::to_string(u.size()) + ")");
  if (AllUncertaintiesWithin(u, kSmallestUncertainty, kLargest, zero_allowed)) return;
  for (std::size_t i = 0; i < n; ++i) {
    const bool ok = std::isfinite(u[i]) && (zero_allowed ? u[i] >= 0.0 : u[i] > 0.0);
    if (!ok)
      throw InputError(At(column, i), std::string("must be finite and ") +
                                          (zero_allowed ? ">= 0" : "> 0") + " for " + method +
                                          " (got " + ExactText(u[i]) + ")");
    if (u[i] > kLargest || (u[i] != 0.0 && u[i] < kSmallestUncertainty))
      throw InputError(At(column, i), "must lie in [1e-100, 1e100] (got " + ExactText(u[i]) +
                                          "): its square or inverse square would overflow a double");
  }
}

}  // namespace

void ValidateLineData(const LineData& data, UncertaintyUse use, const std::string& method) {
  const std::size_t n = data.x.size();
  if (data.y.size() != n)
    throw InputError("Y", "must have one value per row of X (X has " + std::to_string(n) +
                              ", Y has " + std::to_string(data.y.size()) + ")");
  if (n < 2)
    throw InputError("rows",
                     "a straight-line fit needs at least 2 rows (got " + std::to_string(n) + ")");
  RequireFinite(data.x, "X");
  RequireFinite(data.y, "Y");
  bool all_equal = true;
  for (std::size_t i = 1; i < n && all_equal; ++i) all_equal = data.x[i] == data.x[0];
  if (all_equal)
    throw InputError("X", "all " + std::to_string(n) + " values are equal (" + ExactText(data.x[0]) +
                              "), so the slope is undefined: vary the apparatus setting");
  switch (use) {
    case UncertaintyUse::kNone:
      break;
    case UncertaintyUse::kOptionalY:
      if (!data.u_y.empty()) RequireUncertainties(data.u_y, n, "u(Y)", method, false);
      break;
    case UncertaintyUse::kY:
      RequireUncertainties(data.u_y, n, "u(Y)", method, false);
      break;
    case UncertaintyUse::kXY:
      RequireUncertainties(data.u_y, n, "u(Y)", method, false);
      RequireUncertainties(data.u_x, n, "u(X)", method, true);
      break;
  }
}

}  // namespace uphill
