#include "model/propagation.hpp"

#include <ceres/jet.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "model/double_cone_on_line_rails.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "model/scene.hpp"
#include "model/spheroid_on_line_rails.hpp"
#include "internal/spheroid_on_rods_closed_forms.hpp"

namespace uphill {
namespace {

constexpr int kNumInputs = kInputQuantityCount;
constexpr int Index(InputQuantity q) { return static_cast<int>(q); }

// Numbers in messages exactly as stored (as the model's own messages print them).

// ---------------------------------------------------------------------------------------------
// The scene in a form both propagation methods read: which inputs exist, their values and u.

struct Problem {
  UncertainRails::Given given;
  LConvention convention;
  BodyKind body;
  bool rods;  // rod radius > 0
  bool present[kNumInputs] = {};
  double value[kNumInputs] = {};
  double u[kNumInputs] = {};
};

void RequireUncertainty(InputQuantity q, BodyKind body, double u) {
  if (!std::isfinite(u) || u < 0.0)
    throw InputError(std::string("u(") + InputName(q, body) + ")",
                     "must be a finite number >= 0 (got " + ExactText(u) + ")");
}

Problem MakeProblem(const UncertainRails& rails, const UncertainBody& body, Uncertain rod) {
  Problem p;
  p.given = rails.given;
  p.convention = rails.convention;
  p.body = body.kind;
  auto set = [&](InputQuantity q, Uncertain x) {
    RequireUncertainty(q, body.kind, x.u);
    p.present[Index(q)] = true;
    p.value[Index(q)] = x.value;
    p.u[Index(q)] = x.u;
  };
  if (rails.given == UncertainRails::Given::kApparatus) {
    set(InputQuantity::kL, rails.L);
    set(InputQuantity::kH, rails.H);
    set(InputQuantity::kD, rails.D);
  } else {
    set(InputQuantity::kTheta, rails.theta);
    set(InputQuantity::kAlpha, rails.alpha);
  }
  set(InputQuantity::kAcross, body.across);
  if (body.kind != BodyKind::kSphere) set(InputQuantity::kAlong, body.along);
  RequireUncertainty(InputQuantity::kRodRadius, body.kind, rod.u);
  // The model's own checks, with its messages: values finite and in range, the scene modelled.
  const Rails nominal_rails =
      rails.given == UncertainRails::Given::kApparatus
          ? Rails::FromApparatus(rails.L.value, rails.H.value, rails.D.value, rails.convention)
          : Rails::FromAngles(rails.theta.value, rails.alpha.value);
  const Body nominal_body = body.kind == BodyKind::kSphere     ? Body::Sphere(body.across.value)
                            : body.kind == BodyKind::kSpheroid ? Body::Spheroid(body.across.value,
                                                                                body.along.value)
                                                               : Body::DoubleCone(body.across.value,
                                                                                  body.along.value);
  const Scene scene(nominal_body, nominal_rails, rod.value);
  (void)scene;
  p.rods = rod.value > 0.0;
  if (p.rods) {
    set(InputQuantity::kRodRadius, rod);
  } else if (rod.u != 0.0) {
    throw InputError("u(r)", "must be 0 for line rails (r = 0); give r > 0 for round rods (got " +
                                 ExactText(rod.u) + ")");
  }
  return p;
}

void ValidateOptions(const PropagationOptions& o) {
  if (o.trials != 0 && o.trials < 100)
    throw InputError("trials", "must be 0 (first order only) or >= 100 (got " +
                                   std::to_string(o.trials) + ")");
  if (!(o.coverage > 0.0 && o.coverage < 1.0))
    throw InputError("coverage", "must lie in (0, 1) (got " + ExactText(o.coverage) + ")");
  if (!(o.disagreement_tolerance > 0.0) || !std::isfinite(o.disagreement_tolerance))
    throw InputError("disagreement tolerance",
                     "must be a finite number > 0 (got " + ExactText(o.disagreement_tolerance) + ")");
}

// Output slots, in Outputs() order; which exist depends on the body.
enum OutputSlot { kOutTheta, kOutAlpha, kOutPhi, kOutXEq, kOutXMax, kOutTheta0, kOutCount };
constexpr const char* kOutName[kOutCount] = {"theta", "alpha", "phi", "x_eq", "x_max", "theta0"};
constexpr const char* kOutUnit[kOutCount] = {"rad", "rad", "rad", "m", "m", "rad"};

bool HasOutput(BodyKind body, int slot) {
  if (slot == kOutXEq) return body != BodyKind::kDoubleCone;
  if (slot == kOutTheta0) return body == BodyKind::kDoubleCone;
  return true;
}

// ---------------------------------------------------------------------------------------------
// First order: the model's templated closed forms, evaluated on jets.

template <typename S>
void ModelOutputs(const Problem& p, const S (&x)[kNumInputs], S (&y)[kOutCount]) {
  using std::atan2;
  using std::hypot;
  using std::tan;
  S B, T;
  if (p.given == UncertainRails::Given::kApparatus) {
    const S& L = x[Index(InputQuantity::kL)];
    const S& H = x[Index(InputQuantity::kH)];
    const S& D = x[Index(InputQuantity::kD)];
    // As Rails::FromApparatus: the measured ratios, θ and α by atan2.
    const S horizontal = HorizontalDistance(L, H, D, p.convention);
    B = H / horizontal;
    T = D / (2.0 * horizontal);
    y[kOutTheta] = atan2(H, horizontal);
    y[kOutAlpha] = 2.0 * atan2(D / 2.0, horizontal);
  } else {
    // As Rails::FromAngles.
    y[kOutTheta] = x[Index(InputQuantity::kTheta)];
    y[kOutAlpha] = x[Index(InputQuantity::kAlpha)];
    B = tan(y[kOutTheta]);
    T = tan(y[kOutAlpha] / 2.0);
  }
  y[kOutPhi] = atan2(T, hypot(S(1.0), B));  // as Rails::HalfAngleBetweenRails
  const S& across = x[Index(InputQuantity::kAcross)];
  const S& along = x[Index(InputQuantity::kAlong)];
  const S& r = x[Index(InputQuantity::kRodRadius)];
  // As Scene::MakePath.
  switch (p.body) {
    case BodyKind::kSphere: {
      const S R = p.rods ? S(across + r) : across;  // sphere on rods: radius R + r on the axes
      const SpheroidOnLineRails<S> path(R, R, B, T);
      y[kOutXEq] = path.x_eq();
      y[kOutXMax] = path.x_max();
      break;
    }
    case BodyKind::kSpheroid:
      if (p.rods) {
        y[kOutXEq] = SpheroidOnRodsXEq(across, along, B, T, r);
        y[kOutXMax] = SpheroidOnRodsXMax(across, along, T, r);
      } else {
        const SpheroidOnLineRails<S> path(across, along, B, T);
        y[kOutXEq] = path.x_eq();
        y[kOutXMax] = path.x_max();
      }
      break;
    case BodyKind::kDoubleCone: {
      const DoubleConeOnLineRails<S> cone(across, along, B, T);
      y[kOutXMax] = cone.x_fall();
      y[kOutTheta0] = cone.theta0();
      break;
    }
  }
}

void FirstOrder(const Problem& p, PropagatedValue (&out)[kOutCount]) {
  using Jet = ceres::Jet<double, kNumInputs>;
  Jet x[kNumInputs];
  for (int i = 0; i < kNumInputs; ++i) x[i] = Jet(p.value[i], i);
  Jet y[kOutCount];
  ModelOutputs(p, x, y);
  // The values from the same template on doubles: Jet division computes f·(1/g), an ulp away from
  // f/g, and the reported value should be, to the bit, what the scalar model (Scene) gives.
  double value[kOutCount];
  ModelOutputs(p, p.value, value);
  for (int k = 0; k < kOutCount; ++k) {
    if (!HasOutput(p.body, k)) continue;
    PropagatedValue& v = out[k];
    v.name = kOutName[k];
    v.unit = kOutUnit[k];
    v.value = value[k];
    double sum = 0.0;
    for (int i = 0; i < kNumInputs; ++i) {
      if (!p.present[i]) continue;
      v.sensitivity[i] = y[k].v[i];
      // Exactly known inputs contribute exactly nothing (also when a derivative is not finite).
      if (p.u[i] > 0.0) sum += (y[k].v[i] * p.u[i]) * (y[k].v[i] * p.u[i]);
    }
    v.u_first_order = std::sqrt(sum);
  }
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo.

constexpr std::size_t kBlock = 1024;        // trials per block: the working set stays in L2
constexpr std::uint64_t kPilot = 16 * kBlock;  // trials that place the coverage windows
// Half-width of a coverage window in probability, in standard errors of the pilot's quantile
// estimate (sqrt(p(1 − p)/pilot)): 4.5 makes a miss ≈ 7e-6 likely per window end, and a miss
// costs a rerun (time), never accuracy; wider windows cost time on every run (~1 % of the values
// are kept per window end).
constexpr double kWindowSigmas = 4.5;

// SplitMix64 (Steele, Lea, Flood 2014): decorrelated per-input seeds from one user seed.
std::uint64_t SplitMix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

enum Reason : unsigned char {
  kValid = 0,
  kNonPositiveLength,
  kNegativeHeight,
  kAngleOutOfRange,
  kImpossibleApparatus,
  kConeCannotRest,
};

// Running statistics of one output: shifted sums for mean and variance (no cancellation: the
// shift is a sample of the same output), and for each end of the coverage interval a window
// [lo, hi]: values below it are only counted, values inside are kept.
//
// The kept values live in a plain growable array rather than a std::vector so that the AVX2 path
// can store four candidates unconditionally and advance by the number that qualified (branch-
// free), without zero-filling the slack as vector::resize would.
class Kept {
 public:
  std::size_t size() const { return size_; }
  double* begin() { return data_.get(); }
  double* end() { return data_.get() + size_; }
  // Room for `extra` more values (plus slack for a full vector store).
  void Reserve(std::size_t extra) {
    if (size_ + extra + 4 <= capacity_) return;
    const std::size_t capacity = std::max(2 * capacity_, size_ + extra + 4);
    std::unique_ptr<double[]> data(new double[capacity]);
    std::copy(begin(), end(), data.get());
    data_ = std::move(data);
    capacity_ = capacity;
  }
  void Push(double v) {
    Reserve(1);
    data_[size_++] = v;
  }
  void Append(const double* y, std::size_t n) {
    Reserve(n);
    std::copy(y, y + n, end());
    size_ += n;
  }
  void SetEnd(double* end) { size_ = static_cast<std::size_t>(end - data_.get()); }

 private:
  std::unique_ptr<double[]> data_;
  std::size_t size_ = 0, capacity_ = 0;
};

struct Window {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  std::uint64_t below = 0;  // y < lo
  Kept kept;                // lo <= y <= hi
};

struct OutputStats {
  bool varies = true;  // false: depends on no uncertain input, every trial gives `shift`
  bool shifted = false;
  double shift = 0.0;
  double sum = 0.0, sum_c = 0.0;    // Σ(y − shift), Neumaier compensation
  double sum2 = 0.0, sum2_c = 0.0;  // Σ(y − shift)²
  Window window[2];                 // low and high end of the coverage interval
};

void Neumaier(double* sum, double* comp, double x) {
  const double t = *sum + x;
  *comp += std::abs(*sum) >= std::abs(x) ? (*sum - t) + x : (x - t) + *sum;
  *sum = t;
}

// Two-lane vectors (GCC vector extensions: SSE2 on the baseline x86-64 target, generic code
// elsewhere); lane-wise IEEE arithmetic, so the sums are the same on every machine.
using V2d = double __attribute__((vector_size(16)));
using V2i = long __attribute__((vector_size(16)));  // what comparing two V2d gives

void AccumulateMoments(OutputStats& s, const double* y, std::size_t n) {
  // Four independent partial sums (two vectors of two) in a fixed order.
  const V2d shift = {s.shift, s.shift};
  V2d a0 = {0, 0}, a1 = {0, 0}, b0 = {0, 0}, b1 = {0, 0};
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    V2d y0, y1;
    std::memcpy(&y0, y + j, sizeof y0);
    std::memcpy(&y1, y + j + 2, sizeof y1);
    const V2d d0 = y0 - shift, d1 = y1 - shift;
    a0 += d0;
    a1 += d1;
    b0 += d0 * d0;
    b1 += d1 * d1;
  }
  double a = (a0[0] + a0[1]) + (a1[0] + a1[1]), b = (b0[0] + b0[1]) + (b1[0] + b1[1]);
  for (; j < n; ++j) {
    const double d = y[j] - s.shift;
    a += d;
    b += d * d;
  }
  Neumaier(&s.sum, &s.sum_c, a);
  Neumaier(&s.sum2, &s.sum2_c, b);
}

void Keep(Window (&w)[2], double v) {
  for (Window& x : w)
    if (v >= x.lo && v <= x.hi) x.kept.Push(v);
}

// Counts and keeps one block's values for both windows of an output. Counts are exact integers
// and the kept values are appended in order, so both versions give identical results.
void CountWindowsScalar(Window (&w)[2], const double* y, std::size_t n) {
  const double lo0 = w[0].lo, hi0 = w[0].hi, lo1 = w[1].lo, hi1 = w[1].hi;
  std::uint64_t below0 = 0, below1 = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double v = y[j];
    below0 += v < lo0;
    below1 += v < lo1;
    if ((v >= lo0 && v <= hi0) || (v >= lo1 && v <= hi1)) Keep(w, v);  // ~3 % of the values
  }
  w[0].below += below0;
  w[1].below += below1;
}

#if defined(__x86_64__) && defined(__GNUC__)  // the pragma and __builtin_cpu_supports
#define UPHILL_WINDOWS_AVX2 1
// AVX2 by pragma, not by a per-file -mavx2 (see batch_convert.cpp for why); reached only after
// the run-time CPU check.
#pragma GCC push_options
#pragma GCC target("avx2")
// Left-packing permutations: for a 4-bit lane mask, the 32-bit lane indices that move the selected
// doubles to the front, in order.
struct PackTable {
  alignas(32) int idx[16][8];
  int count[16];
  constexpr PackTable() : idx(), count() {
    for (int m = 0; m < 16; ++m) {
      int k = 0;
      for (int lane = 0; lane < 4; ++lane)
        if (m & (1 << lane)) {
          idx[m][2 * k] = 2 * lane;
          idx[m][2 * k + 1] = 2 * lane + 1;
          ++k;
        }
      count[m] = k;
      for (; k < 4; ++k) idx[m][2 * k] = idx[m][2 * k + 1] = 0;
    }
  }
};
constexpr PackTable kPack;

void CountWindowsAvx2(Window (&w)[2], const double* y, std::size_t n) {
  // With ordered, disjoint windows lo0 ≤ hi0 < lo1 ≤ hi1 (always, but for a tiny pilot) four
  // comparisons per value give everything: y is in window 0 iff y ≥ lo0 and not y > hi0, and
  // #(y < lo) = n − #(y ≥ lo), counted as -1 masks. Every step stores its four values, left-
  // packed, at each window's end and advances by the number that qualified: no branch on data.
  if (!(w[0].hi < w[1].lo)) return CountWindowsScalar(w, y, n);
  const __m256d lo0 = _mm256_set1_pd(w[0].lo), hi0 = _mm256_set1_pd(w[0].hi);
  const __m256d lo1 = _mm256_set1_pd(w[1].lo), hi1 = _mm256_set1_pd(w[1].hi);
  w[0].kept.Reserve(n);
  w[1].kept.Reserve(n);
  double* end0 = w[0].kept.end();
  double* end1 = w[1].kept.end();
  __m256i ge0 = _mm256_setzero_si256(), ge1 = _mm256_setzero_si256();
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const __m256d v = _mm256_loadu_pd(y + j);
    const __m256d g0 = _mm256_cmp_pd(v, lo0, _CMP_GE_OQ), g1 = _mm256_cmp_pd(v, hi0, _CMP_GT_OQ);
    const __m256d g2 = _mm256_cmp_pd(v, lo1, _CMP_GE_OQ), g3 = _mm256_cmp_pd(v, hi1, _CMP_GT_OQ);
    ge0 = _mm256_sub_epi64(ge0, _mm256_castpd_si256(g0));
    ge1 = _mm256_sub_epi64(ge1, _mm256_castpd_si256(g2));
    const int m0 = _mm256_movemask_pd(_mm256_andnot_pd(g1, g0));
    const int m1 = _mm256_movemask_pd(_mm256_andnot_pd(g3, g2));
    const __m256i vi = _mm256_castpd_si256(v);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(end0),
                        _mm256_permutevar8x32_epi32(vi, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.idx[m0]))));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(end1),
                        _mm256_permutevar8x32_epi32(vi, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.idx[m1]))));
    end0 += kPack.count[m0];
    end1 += kPack.count[m1];
  }
  w[0].kept.SetEnd(end0);
  w[1].kept.SetEnd(end1);
  alignas(32) long long c0[4], c1[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(c0), ge0);
  _mm256_store_si256(reinterpret_cast<__m256i*>(c1), ge1);
  w[0].below += j - static_cast<std::uint64_t>(c0[0] + c0[1] + c0[2] + c0[3]);
  w[1].below += j - static_cast<std::uint64_t>(c1[0] + c1[1] + c1[2] + c1[3]);
  CountWindowsScalar(w, y + j, n - j);
}
#pragma GCC pop_options
#else
#define UPHILL_WINDOWS_AVX2 0
#endif

void CountWindows(Window (&w)[2], const double* y, std::size_t n, VectorKernel kernel) {
#if UPHILL_WINDOWS_AVX2
  if (kernel != VectorKernel::kScalar && CpuHasAvx2Fma()) return CountWindowsAvx2(w, y, n);
#endif
  (void)kernel;
  CountWindowsScalar(w, y, n);
}

// JCGM 101 §7.7: q = pM if that is an integer, else int(pM + 1/2); r = (M − q)/2 rounded up;
// [y_(r), y_(r+q)], 1-based order statistics. Clamped into [1, M] for tiny M.
void CoverageRanks(std::uint64_t m, double p, std::uint64_t* low, std::uint64_t* high) {
  const double pm = p * static_cast<double>(m);
  std::uint64_t q = static_cast<std::uint64_t>(pm);
  if (static_cast<double>(q) != pm) q = static_cast<std::uint64_t>(pm + 0.5);
  q = std::min(q, m);
  const std::uint64_t r = std::max<std::uint64_t>((m - q + 1) / 2, 1);
  *low = r;
  *high = std::min(r + q, m);
}

// The k-th smallest (1-based) value, or nullopt when the window does not hold it.
std::optional<double> Select(Window& w, std::uint64_t k) {
  if (k <= w.below || k - w.below > w.kept.size()) return std::nullopt;
  double* const it = w.kept.begin() + (k - w.below - 1);
  std::nth_element(w.kept.begin(), it, w.kept.end());
  return *it;
}

struct MonteCarloValue {
  double mean = 0, u = 0, low = 0, high = 0;
};

class MonteCarlo {
 public:
  MonteCarlo(const Problem& p, const PropagationOptions& o) : p_(p), o_(o) {
    for (int k = 0; k < kOutCount; ++k)
      if (HasOutput(p.body, k)) outputs_.push_back(k);
    buffer_.assign(static_cast<std::size_t>(kNumInputs + kOutCount + 3) * kBlock, 0.0);
    for (int i = 0; i < kNumInputs; ++i) std::fill_n(Input(i), kBlock, p.present[i] ? p.value[i] : 0.0);
  }

  // Runs all trials; false if a coverage window missed its order statistic. store_all keeps
  // every value (exact selection: small M, and the rerun after a miss); otherwise a pilot of
  // kPilot trials places the windows.
  bool Run(bool store_all, PropagationResult* result) {
    const std::size_t nout = outputs_.size();
    std::vector<OutputStats> stats(nout);
    for (std::size_t k = 0; k < nout; ++k) stats[k].varies = Varies(outputs_[k]);
    std::vector<std::vector<double>> pilot(nout);
    std::vector<std::vector<double>>* samples = o_.keep_samples ? &result->samples : nullptr;
    if (samples) {
      samples->assign(nout, {});
      for (auto& s : *samples) s.reserve(o_.trials);
    }
    struct Stream {
      int input;
      GaussianStream gauss;
    };
    std::vector<Stream> streams;
    streams.reserve(kNumInputs);
    for (int i = 0; i < kNumInputs; ++i)
      if (p_.present[i] && p_.u[i] > 0.0)
        streams.push_back({i, GaussianStream(SplitMix64(o_.seed + SplitMix64(i)))});

    const bool windows = !store_all && o_.trials > 4 * kPilot;
    RejectedTrials rejected;
    for (std::uint64_t done = 0; done < o_.trials;) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, o_.trials - done));
      for (Stream& s : streams) {
        double* in = Input(s.input);
        s.gauss.Fill(n, in, o_.kernel);
        const double v = p_.value[s.input], u = p_.u[s.input];
        for (std::size_t j = 0; j < n; ++j) in[j] = v + u * in[j];
      }
      const std::size_t valid = Evaluate(n, &rejected);
      for (std::size_t k = 0; k < nout; ++k) {
        const double* y = Output(outputs_[k]);
        OutputStats& s = stats[k];
        if (samples) (*samples)[k].insert((*samples)[k].end(), y, y + valid);
        if (valid == 0) continue;
        if (!s.shifted) {
          s.shifted = true;
          s.shift = y[0];
        }
        if (!s.varies) continue;
        AccumulateMoments(s, y, valid);
        if (!windows) {  // one window holding everything serves both ends
          s.window[0].kept.Append(y, valid);
        } else if (done < kPilot) {
          pilot[k].insert(pilot[k].end(), y, y + valid);
        } else {
          CountWindows(s.window, y, valid, o_.kernel);
        }
      }
      done += n;
      if (windows && done == kPilot) PlaceWindows(pilot, &stats);
    }
    return Finish(stats, rejected, windows, result);
  }

  const MonteCarloValue& value(int slot) const { return values_[slot]; }

 private:
  double* Input(int i) { return buffer_.data() + static_cast<std::size_t>(i) * kBlock; }
  double* Output(int k) { return buffer_.data() + static_cast<std::size_t>(kNumInputs + k) * kBlock; }
  double* Scratch(int s) {
    return buffer_.data() + static_cast<std::size_t>(kNumInputs + kOutCount + s) * kBlock;
  }
  bool Uncertain(InputQuantity q) const { return p_.u[Index(q)] > 0.0; }

  // Whether an output can vary between trials: whether any input it depends on is uncertain.
  // An output that cannot vary gets u = 0 and the interval [y, y] without any statistics. (Were a
  // constant output treated as varying, every value would land in its windows: slow, still exact.)
  bool Varies(int slot) const {
    using Q = InputQuantity;
    auto bit = [](Q q) { return 1u << Index(q); };
    const bool apparatus = p_.given == UncertainRails::Given::kApparatus;
    const bool along_rail = apparatus && p_.convention == LConvention::kAlongRail;
    const unsigned lh = along_rail ? bit(Q::kL) | bit(Q::kH) | bit(Q::kD) : bit(Q::kL);
    // B = tanθ and T = tan(α/2) depend on:
    const unsigned slope_b = apparatus ? lh | bit(Q::kH) : bit(Q::kTheta);
    const unsigned slope_t = apparatus ? lh | bit(Q::kD) : bit(Q::kAlpha);
    const unsigned body = bit(Q::kAcross) | bit(Q::kAlong) | bit(Q::kRodRadius);
    unsigned deps = 0;
    switch (slot) {
      case kOutTheta: deps = slope_b; break;
      case kOutAlpha: deps = slope_t; break;
      case kOutPhi: deps = slope_b | slope_t; break;
      case kOutXEq: deps = slope_b | slope_t | body; break;
      case kOutXMax:  // hypot(a, b/T) (+ r/sin(α/2)); the cone's x_fall = h/T
        deps = p_.body == BodyKind::kDoubleCone ? slope_t | bit(Q::kAlong) : slope_t | body;
        break;
      case kOutTheta0: deps = slope_t | bit(Q::kAcross) | bit(Q::kAlong); break;
    }
    for (int i = 0; i < kNumInputs; ++i)
      if ((deps & (1u << i)) && p_.u[i] > 0.0) return true;
    return false;
  }

  // Screens the block's draws, evaluates the model, and compacts the outputs to the valid trials.
  std::size_t Evaluate(std::size_t n, RejectedTrials* rejected) {
    // Reasons are assigned only once a draw fails: the common case is one vectorised count per
    // uncertain input (the comparisons written with & so that there is no branch to vectorise).
    unsigned char reason[kBlock];
    bool any_bad = false;
    auto mark = [&](std::size_t j, Reason why) {
      if (!any_bad) {
        std::fill(reason, reason + n, kValid);
        any_bad = true;
      }
      if (reason[j] == kValid) reason[j] = why;
    };
    // `bad` is generic: on a double it gives a bool, on a V2d a lane mask (-1 or 0) to count with.
    // Draws are finite (value + u·z), so the comparisons need no NaN care.
    auto screen = [&](InputQuantity q, Reason why, auto bad) {
      if (!Uncertain(q)) return;  // the nominal value passed the model's checks
      const double* x = Input(Index(q));
      V2i count = {0, 0};
      std::size_t j = 0;
      for (; j + 2 <= n; j += 2) {
        V2d v;
        std::memcpy(&v, x + j, sizeof v);
        count -= bad(v);
      }
      bool any = count[0] != 0 || count[1] != 0;
      for (; j < n; ++j) any |= bad(x[j]);
      if (!any) return;
      for (j = 0; j < n; ++j)
        if (bad(x[j])) mark(j, why);
    };
    auto non_positive = [](auto v) { return v <= 0.0; };
    screen(InputQuantity::kL, kNonPositiveLength, non_positive);
    screen(InputQuantity::kD, kNonPositiveLength, non_positive);
    screen(InputQuantity::kAcross, kNonPositiveLength, non_positive);
    screen(InputQuantity::kAlong, kNonPositiveLength, non_positive);
    screen(InputQuantity::kRodRadius, kNonPositiveLength, non_positive);
    screen(InputQuantity::kH, kNegativeHeight, [](auto v) { return v < 0.0; });
    screen(InputQuantity::kTheta, kAngleOutOfRange,
           [](auto v) { return (v < 0.0) | (v >= std::numbers::pi / 2); });
    screen(InputQuantity::kAlpha, kAngleOutOfRange,
           [](auto v) { return (v <= 0.0) | (v >= std::numbers::pi); });
    const bool apparatus = p_.given == UncertainRails::Given::kApparatus;
    const double* L = Input(Index(InputQuantity::kL));
    const double* H = Input(Index(InputQuantity::kH));
    const double* D = Input(Index(InputQuantity::kD));
    if (apparatus && p_.convention == LConvention::kAlongRail &&
        (Uncertain(InputQuantity::kL) || Uncertain(InputQuantity::kH) || Uncertain(InputQuantity::kD))) {
      for (std::size_t j = 0; j < n; ++j)
        if (!(L[j] > std::hypot(H[j], D[j] / 2))) mark(j, kImpossibleApparatus);
    }

    double* B = Scratch(0);
    double* T = Scratch(1);
    RailsArrays rails;
    rails.theta = Output(kOutTheta);
    rails.alpha = Output(kOutAlpha);
    rails.phi = Output(kOutPhi);
    rails.tan_theta = B;
    rails.tan_half_alpha = T;
    if (apparatus) {
      RailsFromApparatusBatch(n, L, H, D, p_.convention, rails, o_.kernel);
    } else {
      RailsFromAnglesBatch(n, Input(Index(InputQuantity::kTheta)), Input(Index(InputQuantity::kAlpha)),
                           rails, o_.kernel);
    }
    const double* across = Input(Index(InputQuantity::kAcross));
    const double* along = Input(Index(InputQuantity::kAlong));
    const double* r = Input(Index(InputQuantity::kRodRadius));
    switch (p_.body) {
      case BodyKind::kSphere: {
        const double* R = across;
        if (p_.rods) {  // as Scene: the sphere of radius R + r on the rods' axes
          double* enlarged = Scratch(2);
          for (std::size_t j = 0; j < n; ++j) enlarged[j] = across[j] + r[j];
          R = enlarged;
        }
        SpheroidBatch(n, R, R, nullptr, B, T, Output(kOutXEq), Output(kOutXMax), o_.kernel);
        break;
      }
      case BodyKind::kSpheroid:
        SpheroidBatch(n, across, along, p_.rods ? r : nullptr, B, T, Output(kOutXEq),
                      Output(kOutXMax), o_.kernel);
        break;
      case BodyKind::kDoubleCone: {
        double* q = Scratch(2);
        DoubleConeBatch(n, across, along, B, T, Output(kOutXMax), Output(kOutTheta0), q, o_.kernel);
        if (!streams_empty())
          for (std::size_t j = 0; j < n; ++j)
            if (!(q[j] > 0.0)) mark(j, kConeCannotRest);
        break;
      }
    }

    if (!any_bad) return n;
    std::size_t bad = 0;
    for (std::size_t j = 0; j < n; ++j) bad += reason[j] != kValid;
    for (std::size_t j = 0; j < n; ++j) {
      switch (reason[j]) {
        case kValid: break;
        case kNonPositiveLength: ++rejected->non_positive_length; break;
        case kNegativeHeight: ++rejected->negative_height; break;
        case kAngleOutOfRange: ++rejected->angle_out_of_range; break;
        case kImpossibleApparatus: ++rejected->impossible_apparatus; break;
        case kConeCannotRest: ++rejected->cone_cannot_rest; break;
      }
    }
    for (int k : outputs_) {
      double* y = Output(k);
      std::size_t w = 0;
      for (std::size_t j = 0; j < n; ++j)
        if (reason[j] == kValid) y[w++] = y[j];
    }
    return n - bad;
  }
  bool streams_empty() const {
    for (int i = 0; i < kNumInputs; ++i)
      if (p_.u[i] > 0.0) return false;
    return true;
  }

  // Windows from the pilot's order statistics at p ± kWindowSigmas·sqrt(p(1 − p)/pilot); the
  // pilot's values then go through them like every later value.
  void PlaceWindows(std::vector<std::vector<double>>& pilot, std::vector<OutputStats>* stats) {
    const double ends[2] = {(1.0 - o_.coverage) / 2, (1.0 + o_.coverage) / 2};
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      std::vector<double>& v = pilot[k];
      OutputStats& s = (*stats)[k];
      if (!s.varies) continue;
      const double m = static_cast<double>(v.size());
      for (int e = 0; e < 2; ++e) {
        Window& w = s.window[e];
        w = Window{};
        if (v.empty()) continue;  // every pilot trial rejected: the window keeps everything
        const double half = kWindowSigmas * std::sqrt(ends[e] * (1.0 - ends[e]) / m);
        const double lo_p = ends[e] - half, hi_p = ends[e] + half;
        if (lo_p > 0.0) {
          const auto it = v.begin() + static_cast<std::ptrdiff_t>(std::floor(lo_p * (m - 1)));
          std::nth_element(v.begin(), it, v.end());
          w.lo = *it;
        }
        if (hi_p < 1.0) {
          const auto it = v.begin() + static_cast<std::ptrdiff_t>(std::ceil(hi_p * (m - 1)));
          std::nth_element(v.begin(), it, v.end());
          w.hi = *it;
        }
        w.kept.Reserve(static_cast<std::size_t>(2.5 * half * static_cast<double>(o_.trials)) + 64);
      }
      CountWindows(s.window, v.data(), v.size(), o_.kernel);
      std::vector<double>().swap(v);
    }
  }

  bool Finish(std::vector<OutputStats>& stats, const RejectedTrials& rejected, bool windows,
              PropagationResult* result) {
    result->rejected = rejected;
    result->valid_trials = o_.trials - rejected.total();
    const std::uint64_t m = result->valid_trials;
    if (m < 2)
      throw InputError("Monte Carlo", "only " + std::to_string(m) + " of " +
                                          std::to_string(o_.trials) +
                                          " trials are physical: the uncertainties are too large "
                                          "for this configuration");
    std::uint64_t rank[2];
    CoverageRanks(m, o_.coverage, &rank[0], &rank[1]);
    bool hit = true;
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      OutputStats& s = stats[k];
      MonteCarloValue& v = values_[outputs_[k]];
      if (!s.varies) {  // exactly the one value every trial gave
        v = MonteCarloValue{s.shift, 0.0, s.shift, s.shift};
        continue;
      }
      const double n = static_cast<double>(m);
      const double sum = s.sum + s.sum_c, sum2 = s.sum2 + s.sum2_c;
      v.mean = s.shift + sum / n;
      v.u = std::sqrt(std::max(0.0, (sum2 - sum * (sum / n)) / (n - 1)));
      for (int e = 0; e < 2; ++e) {
        const std::optional<double> y = Select(windows ? s.window[e] : s.window[0], rank[e]);
        if (!y) {
          hit = false;
          continue;
        }
        (e == 0 ? v.low : v.high) = *y;
      }
    }
    return hit;
  }

  const Problem& p_;
  const PropagationOptions& o_;
  std::vector<int> outputs_;
  std::vector<double> buffer_;
  MonteCarloValue values_[kOutCount];
};

void Flag(PropagatedValue& v, double tolerance) {
  v.disagrees = std::abs(v.u_first_order - v.u_monte_carlo) > tolerance * v.u_monte_carlo;
}

}  // namespace

const char* InputName(InputQuantity quantity, BodyKind body) {
  switch (quantity) {
    case InputQuantity::kL: return "L";
    case InputQuantity::kH: return "H";
    case InputQuantity::kD: return "D";
    case InputQuantity::kTheta: return "theta";
    case InputQuantity::kAlpha: return "alpha";
    case InputQuantity::kAcross: return body == BodyKind::kSpheroid ? "a" : "R";
    case InputQuantity::kAlong: return body == BodyKind::kDoubleCone ? "h" : "b";
    case InputQuantity::kRodRadius: return "r";
  }
  return "?";
}

UncertainRails UncertainRails::Apparatus(Uncertain L, Uncertain H, Uncertain D,
                                         LConvention convention) {
  UncertainRails r;
  r.given = Given::kApparatus;
  r.convention = convention;
  r.L = L;
  r.H = H;
  r.D = D;
  return r;
}

UncertainRails UncertainRails::Angles(Uncertain theta, Uncertain alpha) {
  UncertainRails r;
  r.given = Given::kAngles;
  r.theta = theta;
  r.alpha = alpha;
  return r;
}

UncertainBody UncertainBody::Sphere(Uncertain R) { return UncertainBody{BodyKind::kSphere, R, {}}; }
UncertainBody UncertainBody::Spheroid(Uncertain a, Uncertain b) {
  return UncertainBody{BodyKind::kSpheroid, a, b};
}
UncertainBody UncertainBody::DoubleCone(Uncertain R, Uncertain h) {
  return UncertainBody{BodyKind::kDoubleCone, R, h};
}

std::vector<const PropagatedValue*> PropagationResult::Outputs() const {
  std::vector<const PropagatedValue*> out = {&theta, &alpha, &phi};
  if (x_eq) out.push_back(&*x_eq);
  out.push_back(&x_max);
  if (theta0) out.push_back(&*theta0);
  return out;
}

PropagationResult Propagate(const UncertainRails& rails, const UncertainBody& body,
                            Uncertain rod_radius, const PropagationOptions& options) {
  ValidateOptions(options);
  const Problem p = MakeProblem(rails, body, rod_radius);

  PropagatedValue values[kOutCount];
  FirstOrder(p, values);

  PropagationResult result;
  result.trials = options.trials;
  if (options.trials == 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (PropagatedValue& v : values) v.mc_mean = v.u_monte_carlo = v.coverage_low = v.coverage_high = nan;
  } else {
    MonteCarlo mc(p, options);
    if (!mc.Run(/*store_all=*/false, &result)) {
      // A window missed its order statistic (improbable by design): redo the same trials and
      // select exactly from all of them.
      ++result.window_reruns;
      mc.Run(/*store_all=*/true, &result);
    }
    for (int k = 0; k < kOutCount; ++k) {
      if (!HasOutput(p.body, k)) continue;
      const MonteCarloValue& mcv = mc.value(k);
      values[k].mc_mean = mcv.mean;
      values[k].u_monte_carlo = mcv.u;
      values[k].coverage_low = mcv.low;
      values[k].coverage_high = mcv.high;
      Flag(values[k], options.disagreement_tolerance);
      result.disagrees |= values[k].disagrees;
    }
  }
  result.theta = values[kOutTheta];
  result.alpha = values[kOutAlpha];
  result.phi = values[kOutPhi];
  result.x_max = values[kOutXMax];
  if (HasOutput(p.body, kOutXEq)) result.x_eq = values[kOutXEq];
  if (HasOutput(p.body, kOutTheta0)) result.theta0 = values[kOutTheta0];
  return result;
}

}  // namespace uphill
