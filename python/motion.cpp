// uphill.Motion and uphill.release_times (motion/motion.hpp) over NumPy arrays.
#include <pybind11/stl.h>

#include <cmath>
#include <span>

#include "bindings.hpp"
#include "motion/motion.hpp"

namespace uphill::python {
namespace {

MotionMethod ParseMethod(const std::string& method) {
  if (method == "quadrature") return MotionMethod::kQuadrature;
  if (method == "ode") return MotionMethod::kOde;
  throw InputError("method", "must be \"quadrature\" or \"ode\" (got \"" + method + "\")");
}

py::tuple EventTuple(const MotionEvent& e) { return py::make_tuple(EventName(e.kind), e.t, e.x); }

// Motion.at: the state at every time of t (one library call per element).
py::dict StatesAt(const Motion& motion, const py::handle& t_value) {
  const Float64Argument t(t_value, "t");
  const auto shape = CommonShape({&t});
  const char* names[] = {"t", "x", "z", "v", "vx", "vz", "angle"};
  std::vector<py::array_t<double>> columns;
  std::vector<double*> p;
  for (int k = 0; k < 7; ++k) {
    columns.push_back(NewArray(shape));
    p.push_back(MutableData(columns.back()));
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    MotionSample s;
    try {
      py::gil_scoped_release release;
      s = motion.At(t[i]);
      for (double v : {s.t, s.x, s.z, s.v, s.vx, s.vz, s.angle}) RequireFiniteResult("the state at t", v);
    } catch (const InputError& e) {
      if (t.is_scalar()) throw;
      throw RowInputError(e, i);
    }
    p[0][i] = s.t, p[1][i] = s.x, p[2][i] = s.z, p[3][i] = s.v, p[4][i] = s.vx, p[5][i] = s.vz, p[6][i] = s.angle;
  }
  py::dict out;
  for (int k = 0; k < 7; ++k) out[names[k]] = columns[k];
  return out;
}

py::array_t<double> TimesAt(const Motion& motion, const py::handle& x_value) {
  const Float64Argument x(x_value, "x");
  const auto shape = CommonShape({&x});
  py::array_t<double> t = NewArray(shape);
  double* pt = MutableData(t);
  py::gil_scoped_release release;
  for (std::size_t i = 0; i < x.size(); ++i) pt[i] = motion.TimeAt(x[i]);
  return t;
}

}  // namespace

void BindMotion(py::module_& m) {
  py::class_<Motion>(m, "Motion", R"(The rolling motion of a scene's body released at x0 (motion/motion.hpp).

Motion(scene, x0, v0=0, g=9.80665, mu=0, method="quadrature", tolerance=1e-13): x0 in m (or text
"100 mm"), v0 in m/s (signed, + away from O), g in m/s², mu the rolling-resistance slope threshold
(needs method="ode"), tolerance the relative accuracy target of t and x, in [1e-15, 1e-2]. Ranges
(model/input_ranges.hpp): |v0| <= 1000 m/s, 1e-3 <= g <= 1e3 m/s², 0 <= mu <= 10. Released at rest beyond X
the body rolls away from O until it falls off at x_max; nearer to O it rolls back.
Accuracy: t(x) and x(t) within max(1e-10, 16·cond·1.1e-16) of 25-digit references.)")
      .def(py::init([](const Scene& scene, const py::object& x0, const py::object& v0, const py::object& g,
                       const py::object& mu, const std::string& method, const py::object& tolerance) {
             MotionOptions o;  // v0, g and mu in the ranges of model/input_ranges.hpp (Motion checks them)
             o.v0 = Quantity(v0, Dimension::kVelocity, "v0");
             o.g = Quantity(g, Dimension::kAcceleration, "g");
             o.mu = Number(mu, "mu");
             o.method = ParseMethod(method);
             o.tolerance = Number(tolerance, "tolerance");
             const double start = Quantity(x0, Dimension::kLength, "x0");
             py::gil_scoped_release release;
             return Motion(scene, start, o);
           }),
           py::arg("scene"), py::arg("x0"), py::kw_only(), py::arg("v0") = 0.0, py::arg("g") = 9.80665,
           py::arg("mu") = 0.0, py::arg("method") = "quadrature", py::arg("tolerance") = 1e-13, py::keep_alive<1, 2>())
      .def_property_readonly("x0", &Motion::x0, "Release position, m.")
      .def_property_readonly("direction", &Motion::direction, "+1 away from O, -1 toward O, 0 at rest.")
      .def_property_readonly("end_time", &Motion::end_time,
                             "s: when it falls off or its contact reaches O; inf when neither happens.")
      .def_property_readonly(
          "events",
          [](const Motion& motion) {
            py::list out;
            for (const auto& e : motion.events()) out.append(EventTuple(e));
            return out;
          },
          "Turning points and the final event, in time order: (kind, t in s, x in m), kind one of \"falls off\", "
          "\"reaches O\", \"turning point\", \"comes to rest\".")
      .def("at", &StatesAt, py::arg("t"),
           "The state at t (s; a number or a float64 array, 0 <= t <= end_time): dict of arrays t (s), x, z (m), "
           "v, vx, vz (m/s; v the speed of the centre), angle (rad, rotation since release).")
      .def("time_at", &TimesAt, py::arg("x"),
           "First time (s) the centre is at x (m; a number or a float64 array); inf where it never gets there.")
      .def("position_event", [](const Motion& motion, const py::object& x) { return EventTuple(motion.PositionEvent(Number(x, "x"))); },
           py::arg("x"), "(\"position\", t, x): when the centre first reaches x (m); t = inf if never.");

  m.def(
      "release_times",
      [](const Scene& scene, const py::object& x0, const py::object& xs_value, const py::object& g,
         const py::object& tolerance, const py::object& out) {
        const Float64Argument xs(xs_value, "xs");
        if (xs.is_scalar() || xs.shape().size() != 1) throw InputError("xs", "must be a one-dimensional float64 array");
        ReleaseTimesOptions o;
        o.g = Quantity(g, Dimension::kAcceleration, "g");
        o.tolerance = Number(tolerance, "tolerance");
        const double start = Quantity(x0, Dimension::kLength, "x0");
        py::array_t<double> t = OutputArray(out, "out", xs.shape());
        double* pt = MutableData(t);
        {
          py::gil_scoped_release release;
          ReleaseTimes(scene, start, std::span<const double>(xs.data(), xs.size()), std::span<double>(pt, xs.size()), o);
        }
        return t;
      },
      py::arg("scene"), py::arg("x0"), py::arg("xs"), py::kw_only(), py::arg("g") = 9.80665,
      py::arg("tolerance") = 1e-13, py::arg("out") = py::none(),
      R"(Times (s) at which the body released from rest at x0 (X < x0 < x_max, m) reaches the strictly
increasing positions xs (m, float64 array, x0 < xs <= x_max): the fast whole-trajectory path of
motion/motion.hpp (sphere or spheroid on line rails, sphere on rods). Relative error about
`tolerance`. out=: a float64 array of xs's shape to write into.)");
}

}  // namespace uphill::python
