#include "fit/fit_report.hpp"

#include <stdexcept>

namespace uphill {

std::string MethodName(FitMethod method) {
  switch (method) {
    case FitMethod::kOrdinaryLeastSquares:
      return "ols";
    case FitMethod::kWeightedLeastSquares:
      return "wls";
    case FitMethod::kErrorsInVariables:
      return "york";
    case FitMethod::kRobust:
      return "robust";
    case FitMethod::kFriction:
      return "friction";
  }
  return "unknown";
}

const ParameterEstimate& FitReport::Parameter(std::string_view name) const {
  for (const ParameterEstimate& p : parameters)
    if (p.name == name) return p;
  throw std::out_of_range("fit " + MethodName(method) + " has no parameter '" + std::string(name) +
                          "'");
}

std::optional<double> FitReport::StandardError(std::string_view name, ErrorScaling scaling) const {
  const ParameterEstimate& p = Parameter(name);
  if (scaling == ErrorScaling::kUnscaled) return p.se_unscaled;
  return p.se_scaled;
}

std::optional<Eigen::MatrixXd> FitReport::PrimaryCovariance() const {
  if (primary_scaling == ErrorScaling::kUnscaled) return covariance;
  return covariance_scaled;
}

}  // namespace uphill
