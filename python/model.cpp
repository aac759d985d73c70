// uphill.Body, uphill.Rails, uphill.Scene (model/body.hpp, rails.hpp, scene.hpp) and
// uphill.propagate (model/propagation.hpp).
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "model/propagation.hpp"
#include "model/scene.hpp"

namespace uphill::python {
namespace {

double Angle(const py::handle& v, const char* name) { return Quantity(v, Dimension::kAngle, name); }

// A scene whose positions lie in the lengths' range (model/input_ranges.hpp), as the program's.
Scene CheckedScene(const Body& body, const Rails& rails, double rod_radius) {
  Scene scene(body, rails, rod_radius);
  RequireSceneInRange(scene);
  return scene;
}


// Scene.at over an array of x: one library call per element.
py::dict PathAt(const Scene& scene, const py::handle& x_value) {
  const Float64Argument x(x_value, "x");
  const auto shape = CommonShape({&x});
  py::array_t<double> z = NewArray(shape), dzdx = NewArray(shape), r_star = NewArray(shape), x_contact = NewArray(shape);
  double *pz = MutableData(z), *pd = MutableData(dzdx), *pr = MutableData(r_star), *pc = MutableData(x_contact);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const PathPoint p = ForElement(i, [&] {
      const PathPoint point = scene.At(x[i]);
      RequireFiniteResult("z at x", point.z);
      RequireFiniteResult("dz/dx at x", point.dzdx);  // infinite where the path turns vertical
      RequireFiniteResult("R* at x", point.r_star);
      RequireFiniteResult("the contact at x", point.x_contact);
      return point;
    }, x.is_scalar());
    pz[i] = p.z, pd[i] = p.dzdx, pr[i] = p.r_star, pc[i] = p.x_contact;
  }
  py::dict out;
  out["x"] = x.is_scalar() ? py::object(py::float_(x[0])) : py::object(py::array_t<double>(shape, x.data()));
  out["z"] = z, out["dzdx"] = dzdx, out["r_star"] = r_star, out["x_contact"] = x_contact;
  return out;
}

// Scene.rest over an array of mu.
py::object RestBandAt(const Scene& scene, const py::handle& mu_value) {
  const Float64Argument mu(mu_value, "mu");
  const auto shape = CommonShape({&mu});
  py::array_t<double> low = NewArray(shape), high = NewArray(shape);
  double *pl = MutableData(low), *ph = MutableData(high);
  for (std::size_t i = 0; i < mu.size(); ++i) {
    const std::optional<RestBand> band = ForElement(i, [&] {
      RequireRollingResistance("mu", mu[i]);
      std::optional<RestBand> rest = scene.Rest(mu[i]);
      if (rest) RequireFiniteResult("x_rest", rest->high), RequireFiniteResult("x_rest(-mu)", rest->low);
      return rest;
    }, mu.is_scalar());
    if (!band) return py::none();  // the double cone: see rests_everywhere
    pl[i] = band->low, ph[i] = band->high;
  }
  if (mu.is_scalar()) return py::make_tuple(pl[0], ph[0]);
  return py::make_tuple(low, high);
}

py::dict PropagatedToDict(const PropagatedValue& v, BodyKind body, bool monte_carlo) {
  py::dict d;
  d["value"] = v.value;
  d["unit"] = v.unit;
  d["u_first_order"] = v.u_first_order;
  RequireFiniteResult(v.name, v.value);
  RequireFiniteResult(v.name, v.u_first_order);
  if (monte_carlo) {
    for (double mc : {v.u_monte_carlo, v.mc_mean, v.coverage_low, v.coverage_high}) RequireFiniteResult(v.name, mc);
    d["u_monte_carlo"] = v.u_monte_carlo;
    d["mc_mean"] = v.mc_mean;
    d["coverage_interval"] = py::make_tuple(v.coverage_low, v.coverage_high);
  } else {  // trials = 0: first order only
    for (const char* key : {"u_monte_carlo", "mc_mean", "coverage_interval"}) d[key] = py::none();
  }
  d["disagrees"] = v.disagrees;
  py::dict sensitivity;
  for (int q = 0; q < kInputQuantityCount; ++q) {
    RequireFiniteResult(v.name, v.sensitivity[q]);
    if (v.sensitivity[q] != 0.0) sensitivity[InputName(static_cast<InputQuantity>(q), body)] = v.sensitivity[q];
  }
  d["sensitivity"] = sensitivity;
  return d;
}

// A standard uncertainty (a number or text) in its range (model/input_ranges.hpp); 0 when None.
double Uncertainty(const py::object& u, Dimension dimension, const std::string& name) {
  if (u.is_none()) return 0.0;
  const double v = Quantity(u, dimension, name);
  if (dimension == Dimension::kLength) RequireLengthUncertainty(name, v);
  else RequireAngleUncertainty(name, v);
  return v;
}

// An input with its standard uncertainty, each a number or text, in their ranges.
Uncertain UncertainInput(const py::object& value, const py::object& u, Dimension dimension, const std::string& name) {
  Uncertain out;
  out.value = dimension == Dimension::kLength ? Length(value, name) : Quantity(value, dimension, name);
  out.u = Uncertainty(u, dimension, "u(" + name + ")");
  return out;
}

}  // namespace

void BindModel(py::module_& m) {
  py::class_<Body>(m, "Body", R"(The rolling body, uniform density. Lengths in metres (or text with a unit).

Build with Body.sphere(R), Body.spheroid(a, b) or Body.double_cone(R, h).)")
      .def_static(
          "sphere", [](const py::object& R) { return Body::Sphere(Length(R, "R")); }, py::arg("R"),
          "Sphere of radius R (m, or text such as \"12.7 mm\").")
      .def_static(
          "spheroid", [](const py::object& a, const py::object& b) { return Body::Spheroid(Length(a, "a"), Length(b, "b")); },
          py::arg("a"), py::arg("b"),
          "Spheroid: semi-axis a across the rails (in x and z) and b along the rolling axis y (m, or text).")
      .def_static(
          "double_cone", [](const py::object& R, const py::object& h) { return Body::DoubleCone(Length(R, "R"), Length(h, "h")); },
          py::arg("R"), py::arg("h"), "Double cone of base radius R and half-length h (m, or text).")
      .def_property_readonly("kind", &Body::Name, "\"sphere\", \"spheroid\" or \"double-cone\".")
      .def_readonly("across", &Body::across, "Half-size across the rolling axis: R or a, m.")
      .def_readonly("along", &Body::along, "Half-size along the rolling axis: R (sphere), b (spheroid), h (cone), m.")
      .def_property_readonly("inertia_factor", &Body::InertiaFactor, "I_y/(m·across²): 2/5 (sphere, spheroid), 3/10 (cone).")
      .def("__repr__", [](const Body& b) {
        return "<uphill.Body " + b.Name() + " across=" + std::to_string(b.across) + " m along=" + std::to_string(b.along) + " m>";
      });

  py::class_<Rails>(m, "Rails", R"(The two straight rails that meet at O (angles in radians, lengths in metres).

Build with Rails.from_angles(theta, alpha) or Rails.from_apparatus(L, H, D, along_rail=False).)")
      .def_static(
          "from_angles", [](const py::object& theta, const py::object& alpha) {
            return Rails::FromAngles(Angle(theta, "theta"), Angle(alpha, "alpha"));
          },
          py::arg("theta"), py::arg("alpha"),
          "Inclination theta in [0, pi/2) and divergence alpha in (0, pi): rad, or text (\"10 deg\").")
      .def_static(
          "from_apparatus", [](const py::object& L, const py::object& H, const py::object& D, bool along_rail) {
            return Rails::FromApparatus(Length(L, "L"), Length(H, "H"), Length(D, "D"),
                                        along_rail ? LConvention::kAlongRail : LConvention::kHorizontal);
          },
          py::arg("L"), py::arg("H"), py::arg("D"), py::arg("along_rail") = false,
          "Crossbar measurements (m, or text): distance L from O (horizontal, or along a rail with "
          "along_rail=True), rail height H, rail separation D.")
      .def_readonly("theta", &Rails::theta, "Inclination, rad.")
      .def_readonly("alpha", &Rails::alpha, "Divergence angle in the horizontal projection, rad.")
      .def_readonly("tan_theta", &Rails::tan_theta, "tan(theta), as measured (H/L).")
      .def_readonly("tan_half_alpha", &Rails::tan_half_alpha, "tan(alpha/2), as measured (D/2L).")
      .def_property_readonly("phi", &Rails::HalfAngleBetweenRails, "3-D half angle between the rails, rad.");

  py::class_<Scene>(m, "Scene", R"(One body on one pair of rails (line rails, or round rods of radius rod_radius).

All lengths in metres, angles in radians. Raises InputError when the body cannot rest on both
rails or the scene is not modelled (a double cone on rods).)")
      .def(py::init([](const Body& body, const Rails& rails, const py::object& rod_radius) {
             return CheckedScene(body, rails, rod_radius.is_none() ? 0.0 : Length(rod_radius, "rod_radius"));
           }),
           py::arg("body"), py::arg("rails"), py::arg("rod_radius") = py::none(),
           "Scene(body, rails, rod_radius=None): rod_radius in m (or text); None = line rails.")
      .def_property_readonly("body", &Scene::body)
      .def_property_readonly("rails", &Scene::rails)
      .def_property_readonly("rod_radius", &Scene::rod_radius, "m; 0 for line rails.")
      .def_property_readonly("x_eq", &Scene::x_eq, "X, the unstable equilibrium (maximum of z), m; None for the double cone.")
      .def_property_readonly("z_eq", &Scene::z_eq, "Height of the centre at X, m; None for the double cone.")
      .def_property_readonly("x_max", &Scene::x_max, "Fall-off position, m (double cone: x_fall, where the contact reaches the apex).")
      .def_property_readonly("x_low", &Scene::x_low, "Smallest x of the path (contact at the rails' start), m.")
      .def_property_readonly("rolls_up", &Scene::rolls_up, "Released at rest beyond X it rolls away from O while its centre descends.")
      .def_property_readonly("theta0", &Scene::theta0, "Double cone: critical inclination at fixed alpha, rad (None otherwise).")
      .def_property_readonly("theta0_fixed_phi", &Scene::theta0_fixed_phi,
                             "Double cone: critical inclination at the same 3-D opening, rad (None if there is none).")
      .def("at", &PathAt, py::arg("x"),
           "The path at x (m; a number or a float64 array): dict of x, z (m), dzdx, r_star (m, centre to the "
           "instantaneous axis), x_contact (m). InputError (row = the element) unless x_low <= x <= x_max.")
      .def("rest", &RestBandAt, py::arg("mu"),
           "Rest band (x_rest(-mu), x_rest(mu)) in m for a rolling-resistance coefficient mu >= 0 (a number or a "
           "float64 array: a tuple of arrays); x_rest(mu) is the paper's measured Y. None for the double cone.")
      .def(
          "rests_everywhere",
          [](const Scene& scene, const py::object& mu_value) {
            const double mu = Number(mu_value, "mu");
            RequireRollingResistance("mu", mu);
            return scene.RestsEverywhere(mu);
          },
          py::arg("mu"), "Double cone: its constant slope satisfies |dz/dx| <= mu (0 <= mu <= 10).")
      .def(
          "kinetic_factor",
          [](const Scene& scene, const py::object& x) {
            const double k = scene.KineticFactor(Number(x, "x"));
            RequireFiniteResult("the kinetic factor", k);
            return k;
          },
          py::arg("x"), "1 + I/(m·R*²) at x (m): dimensionless.");

  m.def(
      "propagate",
      [](const Body& body, const py::object& L, const py::object& H, const py::object& D, const py::object& theta,
         const py::object& alpha, const py::object& u_L, const py::object& u_H, const py::object& u_D,
         const py::object& u_theta, const py::object& u_alpha, const py::object& u_across, const py::object& u_along,
         const py::object& rod_radius, const py::object& u_rod_radius, bool along_rail, const py::object& trials,
         const py::object& seed) {
        const bool apparatus = !L.is_none() || !H.is_none() || !D.is_none();
        if (apparatus == (!theta.is_none() || !alpha.is_none()))
          throw InputError("rails", "give either L, H, D or theta, alpha");
        const UncertainRails rails =
            apparatus ? UncertainRails::Apparatus(UncertainInput(L, u_L, Dimension::kLength, "L"),
                                                  UncertainInput(H, u_H, Dimension::kLength, "H"),
                                                  UncertainInput(D, u_D, Dimension::kLength, "D"),
                                                  along_rail ? LConvention::kAlongRail : LConvention::kHorizontal)
                      : UncertainRails::Angles(UncertainInput(theta, u_theta, Dimension::kAngle, "theta"),
                                               UncertainInput(alpha, u_alpha, Dimension::kAngle, "alpha"));
        UncertainBody ubody;
        const Uncertain across{body.across, Uncertainty(u_across, Dimension::kLength, "u_across")};
        const Uncertain along{body.along, Uncertainty(u_along, Dimension::kLength, "u_along")};
        switch (body.kind) {
          case BodyKind::kSphere: ubody = UncertainBody::Sphere(across); break;
          case BodyKind::kSpheroid: ubody = UncertainBody::Spheroid(across, along); break;
          case BodyKind::kDoubleCone: ubody = UncertainBody::DoubleCone(across, along); break;
        }
        Uncertain rods;
        if (!rod_radius.is_none()) rods = UncertainInput(rod_radius, u_rod_radius, Dimension::kLength, "rod_radius");
        PropagationOptions options;
        options.trials = Trials(trials, "trials");
        options.seed = Count(seed, "seed");
        PropagationResult result;
        {
          py::gil_scoped_release release;
          result = Propagate(rails, ubody, rods, options);
        }
        py::dict out;
        for (const PropagatedValue* v : result.Outputs()) out[v->name] = PropagatedToDict(*v, body.kind, options.trials > 0);
        out["trials"] = result.trials;
        out["valid_trials"] = result.valid_trials;
        out["rejected_trials"] = result.rejected.total();
        out["disagrees"] = result.disagrees;
        return out;
      },
      py::arg("body"), py::kw_only(), py::arg("L") = py::none(), py::arg("H") = py::none(), py::arg("D") = py::none(),
      py::arg("theta") = py::none(), py::arg("alpha") = py::none(), py::arg("u_L") = py::none(),
      py::arg("u_H") = py::none(), py::arg("u_D") = py::none(), py::arg("u_theta") = py::none(),
      py::arg("u_alpha") = py::none(), py::arg("u_across") = py::none(), py::arg("u_along") = py::none(),
      py::arg("rod_radius") = py::none(), py::arg("u_rod_radius") = py::none(), py::arg("along_rail") = false,
      py::arg("trials") = 1000000, py::arg("seed") = 1,
      R"(Standard uncertainties of the converter's outputs for one setting (model/propagation.hpp).

First order (GUM, exact derivatives by automatic differentiation) and Monte Carlo (GUM Supplement 1,
`trials` Gaussian trials, 0 = first order only, seeded: the same seed gives the same numbers).
Inputs: the body's dimensions come from `body`, their standard uncertainties from u_across (R or a)
and u_along (b or h); the rails as L, H, D (m) or theta, alpha (rad), each value a number in SI or
text with a unit, u_<name> its standard uncertainty in the same dimension; rod_radius (m) for rods.
Returns a dict keyed by output ("theta", "alpha", "phi" in rad; "x_eq", "x_max" in m; "theta0" in
rad for the cone), each a dict of value, unit, u_first_order, u_monte_carlo, mc_mean,
coverage_interval (95 %), disagrees (first order and Monte Carlo differ by > 5 %) and the
sensitivities (output unit per input unit); plus trials, valid_trials, rejected_trials. With
trials=0 the Monte Carlo entries (u_monte_carlo, mc_mean, coverage_interval) are None; otherwise
trials lies in [100, 10^8]. Lengths and uncertainties in the ranges of model/input_ranges.hpp.)");
}

}  // namespace uphill::python
