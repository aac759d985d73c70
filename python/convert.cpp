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
#include <initializer_list>
#include <map>

#include "bindings.hpp"
#include "model/batch_convert.hpp"
#include "model/propagation.hpp"
#include "model/scene.hpp"

namespace uphill::python {
namespace {

constexpr std::size_t kBlock = 8192;  // 3 inputs + 3 outputs: 384 KB, within L2

// Element i's outputs, each (name, value), finite (model/input_ranges.hpp's last guard), else
// RowInputError naming the first that is not.
void RequireFiniteElement(std::size_t i, std::initializer_list<std::pair<const char*, double>> outputs) {
  ForElement(i, [&] {
    for (const auto& [name, value] : outputs) RequireFiniteResult(name, value);
  });
}

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

// The lengths' ranges of model/input_ranges.hpp, branch-free: a length in [1 nm, 1000 km] (false
// for NaN and the infinities), and H, which may also be 0. The scalar checks name the element.
inline bool InLengthRange(double v) { return (v >= kShortestModelLength) & (v <= kLongestModelLength); }
inline bool HeightInRange(double v) { return (v == 0.0) | InLengthRange(v); }
inline bool ApparatusInRange(double l, double h, double d) { return InLengthRange(l) & HeightInRange(h) & InLengthRange(d); }

__attribute__((target("avx2,fma"))) inline __m256d InLengthRangeAvx2(__m256d v) {
  return _mm256_and_pd(_mm256_cmp_pd(v, _mm256_set1_pd(kShortestModelLength), _CMP_GE_OQ),
                       _mm256_cmp_pd(v, _mm256_set1_pd(kLongestModelLength), _CMP_LE_OQ));
}

// Whether a block of crossbar measurements lies in the ranges, in AVX2 where the CPU has it: the
// ordered comparisons are false for NaN, so a mask of all four lanes means every element is in.
__attribute__((target("avx2,fma"))) bool ApparatusBlockValidAvx2(std::size_t m, const double* L, const double* H,
                                                                   const double* D) {
  __m256d ok = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  std::size_t j = 0;
  for (; j + 4 <= m; j += 4) {
    const __m256d l = _mm256_loadu_pd(L + j), h = _mm256_loadu_pd(H + j), d = _mm256_loadu_pd(D + j);
    const __m256d h_ok = _mm256_or_pd(_mm256_cmp_pd(h, _mm256_setzero_pd(), _CMP_EQ_OQ), InLengthRangeAvx2(h));
    ok = _mm256_and_pd(ok, _mm256_and_pd(_mm256_and_pd(InLengthRangeAvx2(l), InLengthRangeAvx2(d)), h_ok));
  }
  bool all = _mm256_movemask_pd(ok) == 0xF;
  for (; j < m; ++j) all &= ApparatusInRange(L[j], H[j], D[j]);
  return all;
}

bool ApparatusBlockValid(std::size_t m, const double* L, const double* H, const double* D) {
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) return ApparatusBlockValidAvx2(m, L, H, D);
  bool all = true;
  for (std::size_t j = 0; j < m; ++j) all &= ApparatusInRange(L[j], H[j], D[j]);
  return all;
}

// The first element of [0, m) whose output is not finite (model/input_ranges.hpp's last guard),
// or m; several outputs are checked at once.
std::size_t FirstNonFinite(std::size_t m, std::initializer_list<const double*> outputs) {
  return FirstInvalid(m, [&](std::size_t j) {
    bool ok = true;
    for (const double* out : outputs) ok &= std::abs(out[j]) <= DBL_MAX;
    return ok;
  });
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

// Element i's lengths in their ranges (model/input_ranges.hpp), then the model's own rules.
void ElementScene(const ConvertArguments& a, std::size_t i) {
  for (const std::optional<Float64Argument>* length : {&a.L, &a.H, &a.D, &a.across, &a.along, &a.rod_radius})
    if (length->has_value()) RequireModelLength((*length)->name(), (**length)[i]);
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
      // The domain (model/batch_convert.hpp's contract) within the lengths' ranges
      // (model/input_ranges.hpp): lengths in [1 nm, 1000 km], H also 0, along a rail
      // L > hypot(H, D/2); 0 <= theta < pi/2, 0 < alpha < pi; rods > 0.
      const std::size_t bad = FirstInvalid(m, [&](std::size_t j) {
        bool ok = InLengthRange(across[j]) & InLengthRange(along[j]);
        if (rods) ok &= InLengthRange(rods[j]);
        if (a.apparatus()) {
          ok &= ApparatusInRange(x0[j], x1[j], x2[j]);
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
      const std::size_t overflow = FirstNonFinite(m, {p_theta + start, p_alpha + start, p_phi + start, p_first + start,
                                                      p_second + start});
      if (overflow < m) {
        py::gil_scoped_acquire acquire;
        const std::size_t i = start + overflow;
        RequireFiniteElement(i, {{"theta", p_theta[i]}, {"alpha", p_alpha[i]}, {"phi", p_phi[i]},
                                 {cone ? "x_fall" : "X", p_first[i]}, {cone ? "theta0" : "x_max", p_second[i]}});
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
  // An uncertainty of element i in its range (model/input_ranges.hpp), named as given.
  auto get = [&](const std::string& name, std::size_t i) {
    const auto& arg = u.at(name);
    if (!arg) return 0.0;
    const double v = (*arg)[i];
    if (name == "u_theta" || name == "u_alpha") RequireAngleUncertainty(arg->name(), v);
    else RequireLengthUncertainty(arg->name(), v);
    return v;
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
    for (const PropagatedValue* v : r.Outputs())
      RequireFiniteElement(i, {{v->name, v->u_first_order}, {v->name, mc_trials > 0 ? v->u_monte_carlo : 0.0}});
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
         const py::object& mc_trials_value, const py::object& seed_value, const py::kwargs& uncertainties) {
        const std::uint64_t mc_trials = Trials(mc_trials_value, "mc_trials"), seed = Count(seed_value, "seed");
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
Errors: InputError naming the argument and the element (row) outside the model's domain (lengths
and uncertainties in the ranges of model/input_ranges.hpp; mc_trials 0 or in [100, 10^8]), with
the scalar model's own message; mismatched shapes; InputTypeError for a dtype other than float64.)");

  m.def(
      "convert_apparatus",
      [](const py::object& L_value, const py::object& H_value, const py::object& D_value, const py::object& a_value,
         const py::object& b_value, const py::object& theta_out, const py::object& alpha_out,
         const py::object& x_eq_out) {
        const Float64Argument L(L_value, "L"), H(H_value, "H"), D(D_value, "D");
        const double a = Length(a_value, "a"), b = Length(b_value, "b");
        Body::Spheroid(a, b);  // the body's own checks (> 0)
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
            if (!ApparatusBlockValid(m, l, h, d)) {
              const std::size_t bad = FirstInvalid(m, [&](std::size_t j) { return ApparatusInRange(l[j], h[j], d[j]); });
              if (bad < m) {
                py::gil_scoped_acquire acquire;
                const std::size_t i = start + bad;
                ExplainElement(i, [&] {
                  for (const Float64Argument* length : {&L, &H, &D}) RequireModelLength(length->name(), (*length)[i]);
                  Rails::FromApparatus(L[i], H[i], D[i], LConvention::kHorizontal);
                });
              }
            }
            const std::size_t overflow = FirstNonFinite(m, {p_x_eq + start});
            if (overflow < m) {
              py::gil_scoped_acquire acquire;
              RequireFiniteElement(start + overflow, {{"X", p_x_eq[start + overflow]}});
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
Errors: InputError naming the argument and the element outside the domain (L, D and H in
[1 nm, 1000 km], H also 0: model/input_ranges.hpp), with the model's own message.)");
}

}  // namespace uphill::python
