// uphill.convert and uphill.convert_apparatus: the batch kernels of model/batch_convert.hpp over
// NumPy arrays, with the model's domain checked element by element (the offending element's
// message is the scalar model's own: Rails, Body and Scene are asked about it), and, when inputs
// carry uncertainties, model/propagation.hpp per element.
//
// Blocks: the arrays are processed in blocks of kBlock elements, each converted and checked while
// it is in the cache, so the check costs a few vector operations per element and no extra pass
// over memory.
#include <pybind11/stl.h>

#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <functional>
#include <map>

#include "bindings.hpp"
#include "model/batch_convert.hpp"
#include "model/propagation.hpp"
#include "model/scene.hpp"

namespace uphill::python {
namespace {

constexpr std::size_t kBlock = 8192;  // 3 inputs + 3 outputs: 384 KB, within L2

// The scalar model's verdict on element i (throws its InputError as RowInputError); used only
// for an element the bulk check has found outside the domain.
[[noreturn]] void ExplainElement(std::size_t i, const std::function<void()>& build_scene) {
  try {
    build_scene();
  } catch (const InputError& e) {
    throw RowInputError(e, i);
  }
  throw RowInputError(InputError("input", "outside the model's domain"), i);
}

// Index of the first element of [0, m) for which ok(j) is false, or m. Written without
// short-circuits so that the compiler vectorises the common case (all valid).
template <typename Ok>
std::size_t FirstInvalid(std::size_t m, Ok ok) {
  bool all = true;
  for (std::size_t j = 0; j < m; ++j) all &= ok(j);
  if (all) return m;
  for (std::size_t j = 0; j < m; ++j)
    if (!ok(j)) return j;
  return m;
}

inline bool PositiveFinite(double v) { return (v > 0.0) & (v <= DBL_MAX); }
inline bool NonNegativeFinite(double v) { return (v >= 0.0) & (v <= DBL_MAX); }

// Whether a block of crossbar measurements lies in the domain (L, D > 0, H >= 0, all finite), in
// AVX2 where the CPU has it: three minima and one NaN/inf detector (l + h + d)·0, 7 vector
// operations per 4 elements, a few percent of the kernel's work. It can say false for valid
// values near the largest double (l + h + d overflowing): callers then look element by element.
__attribute__((target("avx2,fma"))) bool ApparatusBlockValidAvx2(std::size_t m, const double* L, const double* H,
                                                                   const double* D) {
  const __m256d zero = _mm256_setzero_pd();
  __m256d lo_ld = _mm256_set1_pd(1.0), lo_h = lo_ld, poison = zero;
  std::size_t j = 0;
  for (; j + 4 <= m; j += 4) {
    const __m256d l = _mm256_loadu_pd(L + j), h = _mm256_loadu_pd(H + j), d = _mm256_loadu_pd(D + j);
    lo_ld = _mm256_min_pd(lo_ld, _mm256_min_pd(l, d));
    lo_h = _mm256_min_pd(lo_h, h);
    poison = _mm256_or_pd(poison, _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(l, h), d), zero));  // NaN if any is
  }
  const __m256d ok = _mm256_and_pd(
      _mm256_and_pd(_mm256_cmp_pd(lo_ld, zero, _CMP_GT_OQ), _mm256_cmp_pd(lo_h, zero, _CMP_GE_OQ)),
      _mm256_cmp_pd(poison, zero, _CMP_EQ_OQ));
  bool all = _mm256_movemask_pd(ok) == 0xF;
  for (; j < m; ++j) all &= PositiveFinite(L[j]) & NonNegativeFinite(H[j]) & PositiveFinite(D[j]);
  return all;
}

bool ApparatusBlockValid(std::size_t m, const double* L, const double* H, const double* D) {
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) return ApparatusBlockValidAvx2(m, L, H, D);
  bool all = true;
  for (std::size_t j = 0; j < m; ++j) all &= PositiveFinite(L[j]) & NonNegativeFinite(H[j]) & PositiveFinite(D[j]);
  return all;
}

// A block of an argument: a pointer into its array, or a block filled with its scalar.
struct BlockInput {
  const Float64Argument* argument = nullptr;
  std::vector<double> fill;  // a scalar's block (on the heap: Python threads may have small stacks)
  const double* At(std::size_t start, std::size_t m) {
    if (!argument->is_scalar()) return argument->data() + start;
    fill.assign(m, (*argument)[0]);
    return fill.data();
  }
};

struct ConvertArguments {
  BodyKind body;
  std::optional<Float64Argument> L, H, D, theta, alpha, across, along, rod_radius;
  LConvention convention = LConvention::kHorizontal;
  bool apparatus() const { return L.has_value(); }
};

Body ElementBody(const ConvertArguments& a, std::size_t i) {
  switch (a.body) {
    case BodyKind::kSphere: return Body::Sphere((*a.across)[i]);
    case BodyKind::kSpheroid: return Body::Spheroid((*a.across)[i], (*a.along)[i]);
    case BodyKind::kDoubleCone: return Body::DoubleCone((*a.across)[i], (*a.along)[i]);
  }
  return Body{};
}

Rails ElementRails(const ConvertArguments& a, std::size_t i) {
  return a.apparatus() ? Rails::FromApparatus((*a.L)[i], (*a.H)[i], (*a.D)[i], a.convention)
                       : Rails::FromAngles((*a.theta)[i], (*a.alpha)[i]);
}

void ElementScene(const ConvertArguments& a, std::size_t i) {
  Scene(ElementBody(a, i), ElementRails(a, i), a.rod_radius ? (*a.rod_radius)[i] : 0.0);
}

py::dict Convert(const ConvertArguments& a, const std::vector<py::ssize_t>& shape, std::size_t n) {
  const bool cone = a.body == BodyKind::kDoubleCone;
  if (cone && a.rod_radius) ExplainElement(0, [&] { ElementScene(a, 0); });  // not modelled
  py::array_t<double> theta = NewArray(shape), alpha = NewArray(shape), phi = NewArray(shape);
  py::array_t<double> first = NewArray(shape), second = NewArray(shape);  // x_eq, x_max | x_fall, theta0
  double *p_theta = MutableData(theta), *p_alpha = MutableData(alpha), *p_phi = MutableData(phi);
  double *p_first = MutableData(first), *p_second = MutableData(second);
  {
    py::gil_scoped_release release;
    std::vector<double> tan_theta(kBlock), tan_half_alpha(kBlock), q(kBlock), across_on_rods(kBlock);
    BlockInput in[7];
    const Float64Argument* args[7] = {a.apparatus() ? &*a.L : &*a.theta, a.apparatus() ? &*a.H : &*a.alpha,
                                      a.apparatus() ? &*a.D : &*a.alpha, &*a.across,
                                      a.along ? &*a.along : &*a.across, a.rod_radius ? &*a.rod_radius : &*a.across,
                                      &*a.across};
    for (int k = 0; k < 7; ++k) in[k].argument = args[k];
    for (std::size_t start = 0; start < n; start += kBlock) {
      const std::size_t m = std::min(kBlock, n - start);
      const double *x0 = in[0].At(start, m), *x1 = in[1].At(start, m), *x2 = in[2].At(start, m);
      const double *across = in[3].At(start, m), *along = in[4].At(start, m);
      const double* rods = a.rod_radius ? in[5].At(start, m) : nullptr;
      // The domain (model/batch_convert.hpp's contract): lengths finite and > 0, H finite and
      // >= 0, along a rail L > hypot(H, D/2); 0 <= theta < pi/2, 0 < alpha < pi; rods > 0.
      const std::size_t bad = FirstInvalid(m, [&](std::size_t j) {
        bool ok = PositiveFinite(across[j]) & PositiveFinite(along[j]);
        if (rods) ok &= PositiveFinite(rods[j]);
        if (a.apparatus()) {
          ok &= PositiveFinite(x0[j]) & NonNegativeFinite(x1[j]) & PositiveFinite(x2[j]);
          if (a.convention == LConvention::kAlongRail) ok &= x0[j] > std::hypot(x1[j], x2[j] / 2);
        } else {
          ok &= (x0[j] >= 0.0) & (x0[j] < M_PI / 2) & (x1[j] > 0.0) & (x1[j] < M_PI);
        }
        return ok;
      });
      if (bad < m) {
        py::gil_scoped_acquire acquire;
        ExplainElement(start + bad, [&] { ElementScene(a, start + bad); });
      }
      const RailsArrays rails{p_theta + start, p_alpha + start, p_phi + start, tan_theta.data(), tan_half_alpha.data()};
      if (a.apparatus()) RailsFromApparatusBatch(m, x0, x1, x2, a.convention, rails);
      else RailsFromAnglesBatch(m, x0, x1, rails);
      if (cone) {
        DoubleConeBatch(m, across, along, tan_theta.data(), tan_half_alpha.data(), p_first + start, p_second + start,
                        q.data());
        const std::size_t no_rest = FirstInvalid(m, [&](std::size_t j) { return q[j] > 0.0; });
        if (no_rest < m) {
          py::gil_scoped_acquire acquire;
          ExplainElement(start + no_rest, [&] { ElementScene(a, start + no_rest); });
        }
      } else if (a.body == BodyKind::kSphere && rods) {
        // A sphere on rods is the sphere of radius R + r on the rods' axes (batch_convert.hpp).
        for (std::size_t j = 0; j < m; ++j) across_on_rods[j] = across[j] + rods[j];
        SpheroidBatch(m, across_on_rods.data(), across_on_rods.data(), nullptr, tan_theta.data(),
                      tan_half_alpha.data(), p_first + start, p_second + start);
      } else {
        SpheroidBatch(m, across, along, rods, tan_theta.data(), tan_half_alpha.data(), p_first + start,
                      p_second + start);
      }
    }
  }
  py::dict out;
  out["theta"] = theta, out["alpha"] = alpha, out["phi"] = phi;
  if (cone) {
    out["x_fall"] = first, out["theta0"] = second;
  } else {
    out["x_eq"] = first, out["x_max"] = second;
  }
  return out;
}

// Per element: model/propagation.hpp with the element's values and uncertainties.
void AddUncertainties(const ConvertArguments& a, const std::map<std::string, std::optional<Float64Argument>>& u,
                      std::uint64_t mc_trials, std::uint64_t seed, const std::vector<py::ssize_t>& shape,
                      std::size_t n, py::dict& out) {
  auto get = [&](const std::string& name, std::size_t i) {
    const auto& arg = u.at(name);
    return arg ? (*arg)[i] : 0.0;
  };
  std::map<std::string, py::array_t<double>> first_order, monte_carlo;
  PropagationOptions options;
  options.trials = mc_trials;
  options.seed = seed;
  for (std::size_t i = 0; i < n; ++i) {
    PropagationResult r;
    try {
      const UncertainRails rails =
          a.apparatus()
              ? UncertainRails::Apparatus({(*a.L)[i], get("u_L", i)}, {(*a.H)[i], get("u_H", i)},
                                          {(*a.D)[i], get("u_D", i)}, a.convention)
              : UncertainRails::Angles({(*a.theta)[i], get("u_theta", i)}, {(*a.alpha)[i], get("u_alpha", i)});
      const Uncertain across{(*a.across)[i], get("u_across", i)};
      const Uncertain along{a.along ? (*a.along)[i] : 0.0, get("u_along", i)};
      const UncertainBody body = a.body == BodyKind::kSphere     ? UncertainBody::Sphere(across)
                                 : a.body == BodyKind::kSpheroid ? UncertainBody::Spheroid(across, along)
                                                                 : UncertainBody::DoubleCone(across, along);
      const Uncertain rods{a.rod_radius ? (*a.rod_radius)[i] : 0.0, get("u_rod_radius", i)};
      py::gil_scoped_release release;
      r = Propagate(rails, body, rods, options);
    } catch (const InputError& e) {
      throw RowInputError(e, i);
    }
    for (const PropagatedValue* v : r.Outputs()) {
      const std::string name = v->name;
      if (!first_order.count(name)) {
        first_order.emplace(name, NewArray(shape));
        if (mc_trials > 0) monte_carlo.emplace(name, NewArray(shape));
      }
      MutableData(first_order.at(name))[i] = v->u_first_order;
      if (mc_trials > 0) MutableData(monte_carlo.at(name))[i] = v->u_monte_carlo;
    }
  }
  for (auto& [name, array] : first_order) out[py::str("u_" + name)] = array;
  for (auto& [name, array] : monte_carlo) out[py::str("u_mc_" + name)] = array;
}

}  // namespace

void BindConvert(py::module_& m) {
  m.def(
      "convert",
      [](const std::string& body, const py::object& L, const py::object& H, const py::object& D,
         const py::object& theta, const py::object& alpha, const py::object& R, const py::object& a,
         const py::object& b, const py::object& h, const py::object& rod_radius, bool along_rail,
         std::uint64_t mc_trials, std::uint64_t seed, const py::kwargs& uncertainties) {
        ConvertArguments args;
        args.body = ParseBodyKind(body);
        args.convention = along_rail ? LConvention::kAlongRail : LConvention::kHorizontal;
        auto take = [](const py::object& v, const char* name) {
          return v.is_none() ? std::optional<Float64Argument>() : std::optional<Float64Argument>(Float64Argument(v, name));
        };
        const bool apparatus = !L.is_none() || !H.is_none() || !D.is_none();
        const bool angles = !theta.is_none() || !alpha.is_none();
        if (apparatus == angles) throw InputError("rails", "give either L, H, D or theta, alpha");
        if (apparatus) {
          if (L.is_none() || H.is_none() || D.is_none()) throw InputError("rails", "L, H and D are all needed");
          args.L = take(L, "L"), args.H = take(H, "H"), args.D = take(D, "D");
        } else {
          if (theta.is_none() || alpha.is_none()) throw InputError("rails", "theta and alpha are both needed");
          args.theta = take(theta, "theta"), args.alpha = take(alpha, "alpha");
        }
        const char* across_name = args.body == BodyKind::kSpheroid ? "a" : "R";
        const char* along_name = args.body == BodyKind::kSpheroid ? "b" : "h";
        const py::object& across = args.body == BodyKind::kSpheroid ? a : R;
        const py::object& along = args.body == BodyKind::kSpheroid ? b : h;
        if (across.is_none()) throw InputError(across_name, "is needed for a " + body);
        args.across = take(across, across_name);
        if (args.body != BodyKind::kSphere) {
          if (along.is_none()) throw InputError(along_name, "is needed for a " + body);
          args.along = take(along, along_name);
        }
        args.rod_radius = take(rod_radius, "rod_radius");
        // Uncertainties: u_<input> for the inputs given (u_R / u_a as u_across, u_b / u_h as u_along).
        std::map<std::string, std::optional<Float64Argument>> u;
        for (const char* name : {"u_L", "u_H", "u_D", "u_theta", "u_alpha", "u_across", "u_along", "u_rod_radius"})
          u[name];
        bool any_u = false;
        for (const auto& [key, value] : uncertainties) {
          std::string name = key.cast<std::string>();
          if (name == std::string("u_") + across_name) name = "u_across";
          else if (name == std::string("u_") + along_name && args.along) name = "u_along";
          if (!u.count(name)) throw py::type_error("convert() got an unexpected keyword argument '" + key.cast<std::string>() + "'");
          u[name].emplace(value, key.cast<std::string>());
          any_u = true;
        }
        std::vector<const Float64Argument*> all;
        for (auto* opt : {&args.L, &args.H, &args.D, &args.theta, &args.alpha, &args.across, &args.along, &args.rod_radius})
          if (*opt) all.push_back(&**opt);
        for (auto& [name, arg] : u)
          if (arg) all.push_back(&*arg);
        const auto shape = CommonShape(all);
        const std::size_t n = ElementCount(shape);
        py::dict out = Convert(args, shape, n);
        if (any_u) AddUncertainties(args, u, mc_trials, seed, shape, n, out);
        return out;
      },
      py::arg("body"), py::kw_only(), py::arg("L") = py::none(), py::arg("H") = py::none(), py::arg("D") = py::none(),
      py::arg("theta") = py::none(), py::arg("alpha") = py::none(), py::arg("R") = py::none(),
      py::arg("a") = py::none(), py::arg("b") = py::none(), py::arg("h") = py::none(),
      py::arg("rod_radius") = py::none(), py::arg("along_rail") = false, py::arg("mc_trials") = 0,
      py::arg("seed") = 1,
      R"(Convert many apparatus settings at once: the batch kernel of model/batch_convert.hpp.

body: "sphere" (R), "spheroid" (a, b) or "double-cone" (R, h). Rails: L, H, D (m; the crossbar
distance, horizontal unless along_rail=True, the rail height and separation) or theta, alpha (rad).
rod_radius (m): round rods instead of line rails. Every argument is a number or a float64 array
(SI units); arrays must have one shape, scalars apply to every element.
Returns a dict of float64 arrays of that shape: theta, alpha, phi (rad) and x_eq (X, the unstable
equilibrium) and x_max (fall-off) in m; for the double cone x_fall (m) and theta0 (rad).
Uncertainties: keyword arguments u_L, u_H, u_D, u_theta, u_alpha, u_R / u_a, u_b / u_h,
u_rod_radius (standard uncertainties, same units, scalars or arrays) add u_<output> (first order,
exact derivatives) and, with mc_trials > 0, u_mc_<output> (Monte Carlo, seeded) per element
(model/propagation.hpp; one call per element, microseconds each at first order).
Accuracy: the batch kernel's, within a few ulp of the scalar model (Scene); see uphill.Scene.
Errors: InputError naming the argument and the element (row) outside the model's domain, with the
scalar model's own message; mismatched shapes; TypeError for a dtype other than float64.)");

  m.def(
      "convert_apparatus",
      [](const py::object& L_value, const py::object& H_value, const py::object& D_value, const py::object& a_value,
         const py::object& b_value, const py::object& theta_out, const py::object& alpha_out,
         const py::object& x_eq_out) {
        const Float64Argument L(L_value, "L"), H(H_value, "H"), D(D_value, "D");
        const double a = Quantity(a_value, Dimension::kLength, "a"), b = Quantity(b_value, Dimension::kLength, "b");
        Body::Spheroid(a, b);  // the body's own checks (finite, > 0)
        const auto shape = CommonShape({&L, &H, &D});
        const std::size_t n = ElementCount(shape);
        py::array_t<double> theta = OutputArray(theta_out, "theta", shape), alpha = OutputArray(alpha_out, "alpha", shape),
                            x_eq = OutputArray(x_eq_out, "x_eq", shape);
        double *p_theta = MutableData(theta), *p_alpha = MutableData(alpha), *p_x_eq = MutableData(x_eq);
        {
          py::gil_scoped_release release;
          BlockInput in[3];
          in[0].argument = &L, in[1].argument = &H, in[2].argument = &D;
          for (std::size_t start = 0; start < n; start += kBlock) {
            const std::size_t m = std::min(kBlock, n - start);
            const double *l = in[0].At(start, m), *h = in[1].At(start, m), *d = in[2].At(start, m);
            // The kernel first (it never traps, whatever the input), then the check of the block
            // it has just brought into the cache; outside the domain the call raises.
            ConvertApparatusBatch(m, l, h, d, a, b, p_theta + start, p_alpha + start, p_x_eq + start);
            if (ApparatusBlockValid(m, l, h, d)) continue;
            const std::size_t bad = FirstInvalid(
                m, [&](std::size_t j) { return PositiveFinite(l[j]) & NonNegativeFinite(h[j]) & PositiveFinite(d[j]); });
            if (bad < m) {
              py::gil_scoped_acquire acquire;
              const std::size_t i = start + bad;
              ExplainElement(i, [&] { Rails::FromApparatus(L[i], H[i], D[i], LConvention::kHorizontal); });
            }
          }
        }
        return py::make_tuple(theta, alpha, x_eq);
      },
      py::arg("L"), py::arg("H"), py::arg("D"), py::arg("a"), py::arg("b"), py::kw_only(),
      py::arg("theta") = py::none(), py::arg("alpha") = py::none(), py::arg("x_eq") = py::none(),
      R"(The converter's common case, fast: crossbar L, H, D (m, horizontal L; float64 arrays or
numbers) to (theta, alpha, x_eq) of one spheroid (semi-axes a, b in m; a sphere: a = b = R) on
line rails. theta, alpha in rad, x_eq (X) in m.

The kernel `uphill bench convert` times (ConvertApparatusBatch): libmvec's AVX2 atan where the CPU
has it, within a few ulp of the scalar model. Pass theta=, alpha=, x_eq= (float64, C-contiguous,
the inputs' shape) to write into your own arrays and allocate nothing.
Errors: InputError naming the argument and the element outside the domain (L, D > 0, H >= 0, all
finite), with the model's own message.)");
}

}  // namespace uphill::python
