// The plain-text summary of one line fit, as `uphill fit --xy` prints it (docs/fit.md): the
// method, n and the degrees of freedom; each parameter with its unscaled standard error and,
// where the fit has one, the error scaled by sqrt(χ²/dof); χ², χ²/dof and p; the outliers and
// down-weighted rows (1-based rows of the data) and the fit's notes. Numbers as printed by
// std::ostream's default (6 significant digits), in the data's own units.
#pragma once

#include <string>

#include "fit/fit_report.hpp"

namespace uphill {

std::string FitReportText(const FitReport& report);

}  // namespace uphill
