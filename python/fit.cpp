// The five fits (fit/*.hpp) and their reports: uphill.fit_xy (app/fit_xy.hpp, the use case of
// `uphill fit --xy`, which fit_ols, fit_wls, fit_york and fit_robust call too), fit_friction and
// uphill.FitReport (parameters, covariances, goodness of fit, per-row results as a
// NumPy structured array over the report's own memory).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <regex>

#include "app/fit_xy.hpp"
#include "bindings.hpp"
#include "fit/friction_fit.hpp"
#include "report/fit_json.hpp"

namespace uphill::python {
namespace {

// The fit layer names a bad value "Y[3]": that is element 3 of the argument Y.
[[noreturn]] void RethrowWithRow(const InputError& e) {
  static const std::regex indexed(R"((.*)\[(\d+)\])");
  std::smatch match;
  if (std::regex_match(e.quantity(), match, indexed))
    throw RowInputError(InputError(match[1].str(), e.rule()), std::stoul(match[2].str()));
  throw e;
}

std::vector<double> Column(const py::object& value, const char* name) {
  if (value.is_none()) return {};
  const Float64Argument a(value, name);
  if (a.is_scalar() || a.shape().size() != 1) throw InputError(name, "must be a one-dimensional float64 array");
  return std::vector<double>(a.data(), a.data() + a.size());
}

LineData MakeLineData(const py::object& x, const py::object& y, const py::object& u_x, const py::object& u_y) {
  LineData d;
  d.x = Column(x, "X");
  d.y = Column(y, "Y");
  d.u_x = Column(u_x, "u(X)");
  d.u_y = Column(u_y, "u(Y)");
  return d;
}

// Reads a Python object: called with the GIL, before Run releases it.
FitOptions Options(const py::object& outlier_threshold) {
  FitOptions o;
  o.outlier_threshold = Number(outlier_threshold, "outlier_threshold");
  return o;
}

template <typename F>
FitReport Run(F&& fit) {
  try {
    py::gil_scoped_release release;
    return fit();
  } catch (const InputError& e) {
    RethrowWithRow(e);
  }
}

// A line fit of the use case (app/fit_xy.hpp), the GIL released while it runs.
FitReport LineFit(FitMethod method, const LineData& data, const py::object& outlier_threshold,
                  RobustLoss loss = RobustLoss::kHuber, double loss_scale = 0.0) {
  FitXyOptions options;
  options.fit = Options(outlier_threshold);
  options.loss = loss;
  options.loss_scale = loss_scale;
  return Run([&] { return FitXy(method, data, options); });
}

// One double field of the per-row results as a strided, read-only view of the report's memory.
py::array_t<double> RowField(const py::object& self, double RowResult::*field) {
  const auto& r = self.cast<const FitReport&>();
  const double* first = r.rows.empty() ? nullptr : &(r.rows.front().*field);
  py::array_t<double> view({static_cast<py::ssize_t>(r.rows.size())}, {static_cast<py::ssize_t>(sizeof(RowResult))},
                           first, self);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

py::object Optional(const std::optional<double>& v) { return v ? py::object(py::float_(*v)) : py::none(); }

// The fits' own default (fit/fit_options.hpp), shown in every signature.
constexpr double kOutlierThreshold = FitOptions{}.outlier_threshold;

constexpr const char* kReportDoc = R"(What every fit returns (fit/fit_report.hpp).

parameters: list of Parameter (name, value, se_unscaled, se_scaled); line fits have "k" (slope) and
"c" (intercept, in Y's units), the friction fit "mu" (and "s").
covariance: the stated uncertainties propagated ("unscaled"); covariance_scaled: × chi2/dof (None
when dof = 0); correlation. primary_scaling: which of the two the method's standard errors use.
chi2, dof, reduced_chi2 (MSWD), p_value (upper tail of chi2_dof; None where undefined), r_squared,
aic, bic, exact (N = number of parameters).
rows: NumPy structured array, one record per input row (row, fitted, residual, sigma, normalised,
weight, outlier), a read-only view of the report's memory (no copy); residuals etc. as properties.
outliers (rows with |normalised residual| > outlier_threshold), downweighted (robust fit: (row,
weight, normalised)), notes, solver. to_json(): the dict of `uphill fit --xy ... --json`.)";

}  // namespace

void BindFit(py::module_& m) {
  PYBIND11_NUMPY_DTYPE(RowResult, row, fitted, residual, sigma, normalised, weight, outlier);
  py::class_<ParameterEstimate>(m, "Parameter", "A fitted parameter: name, value, standard errors (unscaled, scaled).")
      .def_readonly("name", &ParameterEstimate::name)
      .def_readonly("value", &ParameterEstimate::value)
      .def_readonly("se_unscaled", &ParameterEstimate::se_unscaled)
      .def_readonly("se_scaled", &ParameterEstimate::se_scaled)
      .def("__repr__", [](const ParameterEstimate& p) {
        return "<uphill.Parameter " + p.name + " = " + std::to_string(p.value) + " ± " + std::to_string(p.se_unscaled) + ">";
      });

  py::class_<FitReport>(m, "FitReport", kReportDoc)
      .def_property_readonly("method", [](const FitReport& r) { return MethodName(r.method); })
      .def_readonly("parameters", &FitReport::parameters)
      .def("parameter", &FitReport::Parameter, py::arg("name"), py::return_value_policy::copy)
      .def_property_readonly("slope", &FitReport::slope, "k of Y = k·X + c (line fits).")
      .def_property_readonly("intercept", &FitReport::intercept, "c of Y = k·X + c (line fits), in Y's units.")
      .def_readonly("covariance", &FitReport::covariance)
      .def_readonly("covariance_scaled", &FitReport::covariance_scaled)
      .def_readonly("correlation", &FitReport::correlation)
      .def_property_readonly("primary_scaling",
                             [](const FitReport& r) { return r.primary_scaling == ErrorScaling::kScaled ? "scaled" : "unscaled"; })
      .def_readonly("uses_stated_uncertainties", &FitReport::uses_stated_uncertainties)
      .def_readonly("n", &FitReport::n)
      .def_readonly("dof", &FitReport::dof)
      .def_readonly("chi2", &FitReport::chi2)
      .def_property_readonly("reduced_chi2", [](const FitReport& r) { return Optional(r.reduced_chi2); })
      .def_property_readonly("p_value", [](const FitReport& r) { return Optional(r.p_value); })
      .def_property_readonly("r_squared", [](const FitReport& r) { return Optional(r.r_squared); })
      .def_property_readonly("aic", [](const FitReport& r) { return Optional(r.aic); })
      .def_property_readonly("bic", [](const FitReport& r) { return Optional(r.bic); })
      .def_readonly("exact", &FitReport::exact)
      .def_readonly("outlier_threshold", &FitReport::outlier_threshold)
      .def_property_readonly(
          "rows",
          [](py::object self) {
            const auto& r = self.cast<const FitReport&>();
            py::array rows(py::dtype::of<RowResult>(), {static_cast<py::ssize_t>(r.rows.size())},
                           {static_cast<py::ssize_t>(sizeof(RowResult))}, r.rows.data(), self);
            rows.attr("setflags")(py::arg("write") = false);
            return rows;
          },
          "Per-row results: structured array (row, fitted, residual, sigma, normalised, weight, outlier), no copy.")
      .def_property_readonly("residuals", [](py::object self) { return RowField(self, &RowResult::residual); },
                             "Y_i − fitted_i, in Y's units (a read-only view of rows[\"residual\"]).")
      .def_property_readonly("normalised_residuals", [](py::object self) { return RowField(self, &RowResult::normalised); },
                             "residual/sigma (a read-only view).")
      .def_property_readonly("fitted", [](py::object self) { return RowField(self, &RowResult::fitted); },
                             "The model at each row (a read-only view).")
      .def_readonly("outliers", &FitReport::outliers)
      .def_property_readonly("downweighted",
                             [](const FitReport& r) {
                               py::list out;
                               for (const auto& d : r.downweighted) out.append(py::make_tuple(d.row, d.weight, d.normalised));
                               return out;
                             })
      .def_readonly("notes", &FitReport::notes)
      .def_property_readonly("solver",
                             [](const FitReport& r) {
                               py::dict d;
                               d["converged"] = r.solver.converged;
                               d["iterations"] = r.solver.iterations;
                               d["termination"] = r.solver.termination;
                               d["refinement_steps"] = r.solver.refinement_steps;
                               return d;
                             })
      .def("to_json", [](const FitReport& r) { return ToPython(FitToJson(r)); },
           "The report as `uphill fit --xy FILE --json` prints it (SI units).")
      .def("__repr__", [](const FitReport& r) {
        std::string s = "<uphill.FitReport " + MethodName(r.method) + " n=" + std::to_string(r.n);
        for (const auto& p : r.parameters) s += " " + p.name + "=" + std::to_string(p.value);
        return s + ">";
      });

  m.def(
      "fit_xy",
      [](const py::object& x, const py::object& y, const py::object& u_x, const py::object& u_y,
         const std::string& method, const py::object& outlier_threshold) {
        const FitMethod m = ParseFitMethod(method, "method");
        return LineFit(m, MakeLineData(x, y, u_x, u_y), outlier_threshold);
      },
      py::arg("x"), py::arg("y"), py::arg("u_x") = py::none(), py::arg("u_y") = py::none(), py::kw_only(),
      py::arg("method") = kDefaultFitXyMethod, py::arg("outlier_threshold") = kOutlierThreshold,
      R"(The line fit of `uphill fit --xy FILE --method METHOD` (app/fit_xy.hpp): method "ols" (the default,
as the command's), "wls", "york" or "robust" (Huber's loss, its default scale); x, y, u_x, u_y
one-dimensional float64 arrays, each
method using the uncertainties it needs (wls: u_y; york: u_x and u_y; robust: u_y when given).
report.to_json() is the command's --json output. Returns a FitReport.)");
  m.def(
      "fit_ols",
      [](const py::object& x, const py::object& y, const py::object& u_x, const py::object& u_y,
         const py::object& outlier_threshold) {
        return LineFit(FitMethod::kOrdinaryLeastSquares, MakeLineData(x, y, u_x, u_y), outlier_threshold);
      },
      py::arg("x"), py::arg("y"), py::arg("u_x") = py::none(), py::arg("u_y") = py::none(), py::kw_only(),
      py::arg("outlier_threshold") = kOutlierThreshold,
      R"(Ordinary least squares Y = k·X + c (the paper's fit; fit/least_squares_line.hpp), with Ceres.
x, y: one-dimensional float64 arrays in any one unit each (u_x, u_y, if given, are ignored, and a
note says so). Standard errors: the usual, scaled by sqrt(chi2/dof). Accuracy: NIST StRD Norris to
12.8-15.5 digits. Returns a FitReport.)");
  m.def(
      "fit_wls",
      [](const py::object& x, const py::object& y, const py::object& u_y, const py::object& u_x,
         const py::object& outlier_threshold) {
        return LineFit(FitMethod::kWeightedLeastSquares, MakeLineData(x, y, u_x, u_y), outlier_threshold);
      },
      py::arg("x"), py::arg("y"), py::arg("u_y"), py::kw_only(), py::arg("u_x") = py::none(),
      py::arg("outlier_threshold") = kOutlierThreshold,
      R"(Weighted least squares with the standard uncertainties u_y (> 0, Y's units); standard errors
unscaled (the stated uncertainties propagated), scaled also given. u_x, if given, is ignored (a
note says so). Returns a FitReport.)");
  m.def(
      "fit_york",
      [](const py::object& x, const py::object& y, const py::object& u_x, const py::object& u_y, const py::object& outlier_threshold) {
        return LineFit(FitMethod::kErrorsInVariables, MakeLineData(x, y, u_x, u_y), outlier_threshold);
      },
      py::arg("x"), py::arg("y"), py::arg("u_x"), py::arg("u_y"), py::kw_only(), py::arg("outlier_threshold") = kOutlierThreshold,
      R"(Errors in both variables: the maximum-likelihood line of York et al. (2004)
(fit/york_line.hpp). u_x >= 0 and u_y > 0 are standard uncertainties in X's and Y's units.
Standard errors unscaled (York's), scaled also given. Returns a FitReport.)");
  m.def(
      "fit_robust",
      [](const py::object& x, const py::object& y, const py::object& u_y, const py::object& u_x, const std::string& loss,
         const py::object& loss_scale, const py::object& outlier_threshold) {
        const LineData d = MakeLineData(x, y, u_x, u_y);
        RobustLoss kind = RobustLoss::kHuber;
        if (loss == "cauchy") kind = RobustLoss::kCauchy;
        else if (loss != "huber") throw InputError("loss", "must be \"huber\" or \"cauchy\" (got \"" + loss + "\")");
        return LineFit(FitMethod::kRobust, d, outlier_threshold, kind, Number(loss_scale, "loss_scale"));
      },
      py::arg("x"), py::arg("y"), py::arg("u_y") = py::none(), py::kw_only(), py::arg("u_x") = py::none(),
      py::arg("loss") = "huber",
      py::arg("loss_scale") = 0.0, py::arg("outlier_threshold") = kOutlierThreshold,
      R"(A robust line (fit/robust_line.hpp): Huber's or Cauchy's loss with Ceres; sigma from u_y
when given, else a robust scale (1.4826·MAD). loss_scale in units of sigma (0: the loss's default,
95 % efficiency). FitReport.downweighted names the rows it trusts less. Returns a FitReport.)");
  m.def(
      "fit_friction",
      [](const std::vector<Scene>& scenes, const py::object& y, const py::object& u_y, const py::object& u_model,
         bool fit_scale, const py::object& outlier_threshold) {
        FrictionData d;
        d.scenes = scenes;
        d.y = Column(y, "Y");
        d.u_y = Column(u_y, "u(Y)");
        d.u_model = Column(u_model, "u_model");
        // Positions and their uncertainties in the lengths' ranges (model/input_ranges.hpp), as
        // the experiment reader holds Y and u(Y) for `uphill fit`.
        for (std::size_t i = 0; i < d.y.size(); ++i) ForElement(i, [&] { RequireModelLength("Y", d.y[i]); });
        for (std::size_t i = 0; i < d.u_y.size(); ++i) ForElement(i, [&] { RequireLengthUncertainty("u(Y)", d.u_y[i]); });
        for (std::size_t i = 0; i < d.u_model.size(); ++i)
          ForElement(i, [&] { RequireLengthUncertainty("u_model", d.u_model[i]); });
        FrictionOptions o;
        o.fit_scale = fit_scale;
        o.fit = Options(outlier_threshold);
        return Run([&] { return FitFriction(d, o); });
      },
      py::arg("scenes"), py::arg("y"), py::arg("u_y") = py::none(), py::kw_only(), py::arg("u_model") = py::none(),
      py::arg("fit_scale") = false, py::arg("outlier_threshold") = kOutlierThreshold,
      R"(The rolling-resistance model fitted to measured farthest rest positions (fit/friction_fit.hpp):
Y_i = s·x_rest,i(mu), mu >= 0 (and s with fit_scale=True). scenes: one uphill.Scene per row; y, u_y,
u_model: float64 arrays in m (u_model: the model value's own standard uncertainty, needs u_y).
Returns a FitReport with the parameter "mu" (dimensionless) and "s".)");
}

}  // namespace uphill::python
