// Propagate: standard uncertainties of the measured inputs to the converter's outputs, two ways.
//
//   first order (GUM, JCGM 100 §5.1.2)  u_y² = Σ_i (∂y/∂x_i · u_i)², uncorrelated inputs, with the
//       sensitivities ∂y/∂x_i by automatic differentiation (ceres::Jet) through the same templated
//       closed forms the model evaluates (HorizontalDistance, SpheroidOnLineRails,
//       DoubleConeOnLineRails, spheroid_on_rods_closed_forms.hpp). Exact derivatives, no step.
//   Monte Carlo (GUM Supplement 1, JCGM 101)  Gaussian inputs N(x_i, u_i²), M trials (default
//       10^6); per output the mean, the standard deviation (divisor M − 1) and the
//       probabilistically symmetric 95 % coverage interval [y_(r), y_(r+q)], q = pM rounded,
//       r = (M − q)/2 rounded up (JCGM 101 §7.7), from exact order statistics.
//       Mean and u come from the shifted sums S1 = Σ(y − s), S2 = Σ(y − s)², s = the first valid
//       trial's value (a sample, so |ȳ − s| is a few u), as plain sums over each block of 2048
//       trials added up with Neumaier's compensation: u² = (S2 − S1²/M)/(M − 1) then loses
//       relative accuracy ≈ 2^-53·(2048 + (ȳ − s)²/u²)·a few, i.e. u is good to ~1e-12 or better
//       (the statistical error, 1/sqrt(2M), is ~1e-3); the mean to ~1e-13·u.
//
// The two agree when the model is close to linear over ± a few u; where they do not, the first-
// order value is the one that is wrong, and the output (and the result) is flagged: `disagrees`
// is set when |u_first_order − u_monte_carlo| > disagreement_tolerance · u_monte_carlo (5 %).
//
// Inputs (SI: metres, radians), each a value with its standard uncertainty u ≥ 0 (0 = exact):
//   rails   the crossbar measurements L, H, D with the L convention, or the angles θ, α;
//   body    sphere R; spheroid a, b; double cone R, h;
//   rods    radius r (0 = line rails, then u(r) must be 0). A double cone on rods is not modelled.
// Outputs: θ, α, φ (rad); x_eq = X, the unstable equilibrium (m, sphere and spheroid); x_max (m),
// the fall-off (for the double cone x_fall = h·cot(α/2), where the contact reaches the apex);
// θ0 (rad, double cone: critical inclination at fixed α).
//
// Unphysical draws. A Gaussian draw can leave the model's domain (a length ≤ 0, H < 0, an angle out
// of range, an along-rail L ≤ hypot(H, D/2), a double cone that cannot rest on both rails). Such
// trials are counted by reason in `rejected` and left out of the statistics, which then describe
// the inputs' distribution truncated to the physical domain. A non-zero count means that the
// uncertainties are large for this configuration: say so to the user.
//
// Reproducibility. Each input has its own counter-based stream: Random123's Philox4x32-10 with
// key = options.seed and the input's index (InputQuantity, 0 … kNumInputs − 1) as the stream id
// in the counter, turned into standard normal deviates by a 1024-layer ziggurat with fixed,
// generated tables: GaussianStream (gaussian_stream.hpp, which states the stream operation by
// operation; its AVX2 and scalar kernels give the same bits). Input i of trial k is
// value_i + u_i·z_k (one multiplication, one addition) with z_k the k-th deviate of stream i. So
// the trials' inputs depend only on the seed (not on the machine, the compiler or a library's
// version; the rare tail deviates up to the C library's log in the last bit), and a draw of D
// does not change when another input gains or loses its uncertainty. The outputs
// come from the batch kernel's expressions (batch_convert.hpp): the same numbers on every run, to
// a few ulp the same on another CPU (kScalar and kAvx2 differ in the last bits; options.kernel
// picks one). kScalar is the model's own scalar code. kAvx2 evaluates the angles θ = atan(B),
// α = 2·atan(T), φ = atan(T/hypot(1, B)) not by libmvec but by NarrowAtan
// (internal/narrow_atan.hpp): the Taylor polynomial of atan about a centre fixed at the first
// block (the midpoint of its arguments' bounds), of the degree each block's bounds need for a
// truncation ≤ 2^-56 relative, within 0.6 ulp of atan in the lab's cases (libmvec: 4 ulp); a
// block whose arguments are too spread for it uses libmvec. So a trial's angle can depend in its
// last bit on the block it falls in, never on the machine. For the common case (apparatus with
// the horizontal L, sphere or spheroid on line rails) the model runs in one pass per block.
//
// Values. `value` is the scalar model's (Scene's) value to the bit; the sensitivities come from
// jets through the same expressions. (The jets' own values can differ in the last bit: Jet
// division multiplies by a reciprocal.)
//
// Cost: first order is one evaluation with 8-component jets (microseconds). Monte Carlo runs in
// blocks of 2048 trials with no per-trial allocation and no virtual dispatch; the coverage
// interval is found without sorting the M values: a pilot of 2^12 trials places a window of
// ± 4.5 standard errors around each quantile, narrowed from the exact order statistics so far
// after 2^15 trials and after each further factor 8; the trials are only counted (below a
// window) or kept (inside) — exact, with an exact rerun in the (≈ 1e-4 probable) case that a
// window misses. Memory: under 1 % of M per output (≈ 3 000 values per window end at M = 10^6).
// `uphill bench convert` measures the cost per trial against NumPy (docs/benchmarks.md).

// Errors: InputError (model/input_error.hpp) naming the quantity and the rule, for a bad value
// (the model's own checks: e.g. "D: must be > 0 (got -0.003)"), a bad uncertainty
// ("u(D): must be a finite number >= 0 (got nan)"), bad options, or Monte Carlo trials of which
// fewer than 2 are physical.
//
// Usage:
//
//   using uphill::Uncertain;
//   const auto rails = uphill::UncertainRails::Apparatus(
//       Uncertain{1.165, 0.002}, Uncertain{0.300, 0.001}, Uncertain{0.045, 0.0005});  // metres
//   const auto body = uphill::UncertainBody::Spheroid(Uncertain{0.015875, 2e-5},
//                                                     Uncertain{0.0254, 2e-5});
//   uphill::PropagationOptions options;   // 10^6 trials, seed 1, 95 %, 5 % tolerance
//   const uphill::PropagationResult res = uphill::Propagate(rails, body, Uncertain{}, options);
//   for (const uphill::PropagatedValue* y : res.Outputs())
//     std::printf("%-6s = %.6g %s  u = %.2g (first order) / %.2g (MC), 95 %% [%.6g, %.6g]%s\n",
//                 y->name, y->value, y->unit, y->u_first_order, y->u_monte_carlo,
//                 y->coverage_low, y->coverage_high, y->disagrees ? "  (nonlinear: use MC)" : "");
//   if (res.rejected.total() > 0) { /* warn: res.rejected.total() of res.trials were unphysical */ }
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "model/batch_convert.hpp"
#include "model/body.hpp"
#include "model/rails.hpp"

namespace uphill {

// A value and its standard uncertainty, in the same unit (SI in the library).
struct Uncertain {
  double value = 0.0;
  double u = 0.0;  // standard uncertainty, finite, >= 0; 0: exactly known
};

// The inputs that can carry an uncertainty; the index into PropagatedValue::sensitivity.
// kAcross is R (sphere, double cone) or a (spheroid); kAlong is b (spheroid) or h (double cone).
enum class InputQuantity { kL, kH, kD, kTheta, kAlpha, kAcross, kAlong, kRodRadius };
inline constexpr int kInputQuantityCount = 8;
// "L", "H", "D", "theta", "alpha", "R"/"a", "b"/"h", "r" (the name for the given body).
const char* InputName(InputQuantity quantity, BodyKind body);

// The rails, as the lab measured them or as angles. Build with the factories.
struct UncertainRails {
  enum class Given { kApparatus, kAngles };

  // Crossbar measurements, metres (rails.hpp: convention, tanθ = H/Lh, tan(α/2) = D/(2·Lh)).
  static UncertainRails Apparatus(Uncertain L, Uncertain H, Uncertain D,
                                  LConvention convention = LConvention::kHorizontal);
  // Inclination θ and divergence α, radians.
  static UncertainRails Angles(Uncertain theta, Uncertain alpha);

  Given given = Given::kApparatus;
  LConvention convention = LConvention::kHorizontal;
  Uncertain L, H, D;     // given == kApparatus
  Uncertain theta, alpha;  // given == kAngles
};

// The body's dimensions, metres. Build with the factories.
struct UncertainBody {
  static UncertainBody Sphere(Uncertain R);
  static UncertainBody Spheroid(Uncertain a, Uncertain b);
  static UncertainBody DoubleCone(Uncertain R, Uncertain h);

  BodyKind kind = BodyKind::kSphere;
  Uncertain across;  // R (sphere, double cone) or a (spheroid)
  Uncertain along;   // b (spheroid) or h (double cone); unused for the sphere
};

struct PropagationOptions {
  // Monte Carlo trials M. 0 skips Monte Carlo (first order only; its fields are then NaN and
  // nothing is flagged); otherwise at least 100. JCGM 101 §7.2.2 asks for M ≫ 1/(1 − p), e.g.
  // 10^4/(1 − p) = 2·10^5 for a 95 % interval; the default 10^6 gives u to about 0.1 %.
  std::uint64_t trials = 1'000'000;
  std::uint64_t seed = 1;
  double coverage = 0.95;                // p of the coverage interval, in (0, 1)
  double disagreement_tolerance = 0.05;  // relative to u_monte_carlo, > 0
  // Keep every output's valid trial values in PropagationResult::samples (M doubles each), for
  // histograms or tests. Off by default: the statistics never need them.
  bool keep_samples = false;
  // The per-trial model; kAuto is the fastest available (see batch_convert.hpp).
  VectorKernel kernel = VectorKernel::kAuto;
};

// One output: the model's value at the input values and its uncertainty both ways.
struct PropagatedValue {
  const char* name = "";  // "theta", "alpha", "phi", "x_eq", "x_max", "theta0"
  const char* unit = "";  // "rad" or "m"
  double value = 0.0;     // the model at the input values: the GUM estimate y = f(x)
  // First order: u_y and the sensitivities ∂y/∂x_i (output unit per input unit; 0 for inputs
  // this output does not depend on or that the scene does not have), indexed by InputQuantity.
  double u_first_order = 0.0;
  std::array<double, kInputQuantityCount> sensitivity{};
  // Monte Carlo over the valid trials (NaN when options.trials == 0).
  double mc_mean = 0.0;
  double u_monte_carlo = 0.0;  // sample standard deviation, divisor M_valid − 1
  double coverage_low = 0.0;   // probabilistically symmetric interval, probability options.coverage
  double coverage_high = 0.0;
  // |u_first_order − u_monte_carlo| > tolerance · u_monte_carlo (also when u_monte_carlo = 0 <
  // u_first_order). First order is then not to be trusted for this output.
  bool disagrees = false;

  double sensitivity_to(InputQuantity q) const { return sensitivity[static_cast<int>(q)]; }
};

// Monte Carlo trials left out of the statistics, by the first reason that applies.
struct RejectedTrials {
  std::uint64_t non_positive_length = 0;   // L, D, R, a, b, h or r (on rods) drawn ≤ 0
  std::uint64_t negative_height = 0;       // H drawn < 0
  std::uint64_t angle_out_of_range = 0;    // θ ∉ [0, π/2) or α ∉ (0, π)
  std::uint64_t impossible_apparatus = 0;  // along-rail L ≤ hypot(H, D/2)
  std::uint64_t cone_cannot_rest = 0;      // 1 + tan²θ − (R/h)²tan²(α/2) ≤ 0
  std::uint64_t total() const {
    return non_positive_length + negative_height + angle_out_of_range + impossible_apparatus +
           cone_cannot_rest;
  }
};

struct PropagationResult {
  PropagatedValue theta, alpha, phi;
  std::optional<PropagatedValue> x_eq;  // sphere and spheroid
  PropagatedValue x_max;                // fall-off; for the double cone x_fall
  std::optional<PropagatedValue> theta0;  // double cone

  std::uint64_t trials = 0;        // M asked for
  std::uint64_t valid_trials = 0;  // M − rejected.total(): the statistics' sample size
  RejectedTrials rejected;
  bool disagrees = false;          // any output's flag
  int window_reruns = 0;           // diagnostic: exact reruns after a coverage window missed

  // The present outputs in the fixed order θ, α, φ, x_eq, x_max, θ0 (for printing).
  std::vector<const PropagatedValue*> Outputs() const;
  // With options.keep_samples: the valid trials' values per output, in Outputs() order.
  std::vector<std::vector<double>> samples;
};

// Validates everything (throws InputError), then propagates. rod_radius.value 0: line rails.
PropagationResult Propagate(const UncertainRails& rails, const UncertainBody& body,
                            Uncertain rod_radius = {}, const PropagationOptions& options = {});

}  // namespace uphill
