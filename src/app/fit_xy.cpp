#include "app/fit_xy.hpp"

#include "fit/least_squares_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"

namespace uphill {

FitMethod ParseFitMethod(const std::string& name, const std::string& quantity) {
  if (name == "ols") return FitMethod::kOrdinaryLeastSquares;
  if (name == "wls") return FitMethod::kWeightedLeastSquares;
  if (name == "york") return FitMethod::kErrorsInVariables;
  if (name == "robust") return FitMethod::kRobust;
  throw InputError(quantity, "must be ols, wls, york or robust (got '" + name + "')");
}

FitReport FitXy(FitMethod method, const LineData& data, const FitXyOptions& options) {
  switch (method) {
    case FitMethod::kOrdinaryLeastSquares:
      return FitOrdinaryLeastSquares(data, options.fit);
    case FitMethod::kWeightedLeastSquares:
      return FitWeightedLeastSquares(data, options.fit);
    case FitMethod::kErrorsInVariables:
      return FitErrorsInVariables(data, options.fit);
    case FitMethod::kRobust: {
      RobustOptions robust;
      robust.loss = options.loss;
      robust.loss_scale = options.loss_scale;
      robust.fit = options.fit;
      return FitRobust(data, robust);
    }
    case FitMethod::kFriction:
      break;
  }
  throw InputError("method", "the friction model is fitted to an experiment's scenes, not to X-Y data");
}

}  // namespace uphill
