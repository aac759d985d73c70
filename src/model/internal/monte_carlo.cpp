#include "monte_carlo.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include "batch_kernels_avx2.hpp"
#include "coverage_windows.hpp"
#include "monte_carlo_avx2.hpp"
#include "narrow_atan.hpp"
#include "model/batch_convert.hpp"
#include "model/gaussian_stream.hpp"
#include "model/input_error.hpp"

namespace uphill::internal {
namespace {

// ---------------------------------------------------------------------------------------------
// Monte Carlo.

constexpr std::size_t kBlock = 2048;        // trials per block: the working set (~300 KB) stays in L2
constexpr std::uint64_t kPilot = 2 * kBlock;   // trials that place the coverage windows
// The block's arrays lie kStride doubles apart: 64 bytes more than a block, so that they do not
// all fall on the same L1 cache sets (a block apart, a multiple of the 4 KB set period, the
// thirteen arrays a pass touches would contend for the 8 ways of the same sets).
constexpr std::size_t kStride = kBlock + 8;
// Half-width of a coverage window in probability, in standard errors of the quantile estimate
// that places it (sqrt(p(1 − p)/m) after m trials): 4.5 makes a miss ≈ 7e-6 likely per window
// end, and a miss costs a rerun (time), never accuracy; wider windows cost time on every run
// (the pilot's keep ≈ 2 % of the values per window end, narrowed ones less).
constexpr double kWindowSigmas = 4.5;
// The windows are narrowed again (NarrowWindows) after kNarrowEvery·kPilot trials, and after each
// further factor kNarrowEvery: each time to sqrt(kNarrowEvery) ≈ 2.8 times narrower.
constexpr std::uint64_t kNarrowEvery = 8;

enum Reason : unsigned char {
  kValid = 0,
  kNonPositiveLength,
  kNegativeHeight,
  kAngleOutOfRange,
  kImpossibleApparatus,
  kConeCannotRest,
};

// Running statistics of one output: shifted sums for mean and variance (no cancellation: the
// shift is a sample of the same output), and the two coverage windows (coverage_windows.hpp).
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

// Puts base[r] in place for every rank r of [r_begin, r_end) (distinct, ascending, each inside
// [first, last)) as std::nth_element would: the middle rank first, then each side within its
// part, so that the four ends of two coverage windows cost two passes over the pilot, not four.
void SelectRanks(double* first, double* last, const std::ptrdiff_t* r_begin, const std::ptrdiff_t* r_end,
                 double* base) {
  if (r_begin == r_end || first >= last) return;
  const std::ptrdiff_t* mid = r_begin + (r_end - r_begin) / 2;
  double* nth = base + *mid;
  std::nth_element(first, nth, last);
  SelectRanks(first, nth, r_begin, mid, base);
  SelectRanks(nth + 1, last, mid + 1, r_end, base);
}

class MonteCarloRun {
 public:
  MonteCarloRun(const Problem& p, const PropagationOptions& o) : p_(p), o_(o) {
    for (int k = 0; k < kOutCount; ++k)
      if (HasOutput(p.body, k)) outputs_.push_back(k);
    buffer_.assign(static_cast<std::size_t>(kNumInputs + kOutCount + 4) * kStride, 0.0);
#if defined(__x86_64__) && defined(__GNUC__)
    narrow_ = UseAvx2(o.kernel);
#endif
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
        streams.push_back({i, GaussianStream(o_.seed, static_cast<std::uint32_t>(i))});

    const bool windows = !store_all && o_.trials > 4 * kPilot;
    std::uint64_t narrow_at = kNarrowEvery * kPilot;
    RejectedTrials rejected;
    for (std::uint64_t done = 0; done < o_.trials;) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, o_.trials - done));
      for (Stream& s : streams) {
        range_[s.input] = s.gauss.FillScaled(n, p_.value[s.input], p_.u[s.input], Input(s.input), o_.kernel);
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
        if (!windows) {  // one window holding everything serves both ends
          AccumulateMoments(s, y, valid);
          s.window[0].kept.Append(y, valid);
        } else if (done < kPilot) {
          AccumulateMoments(s, y, valid);
          pilot[k].insert(pilot[k].end(), y, y + valid);
        } else {  // the moments' sums in the windows' pass over the values
          BlockSums sums{s.shift};
          CountWindows(s.window, y, valid, o_.kernel, &sums);
          Neumaier(&s.sum, &s.sum_c, sums.sum);
          Neumaier(&s.sum2, &s.sum2_c, sums.sum2);
        }
      }
      done += n;
      if (windows && done == kPilot) PlaceWindows(pilot, &stats);
      if (windows && done == narrow_at && done < o_.trials) {
        NarrowWindows(done - rejected.total(), &stats);
        narrow_at *= kNarrowEvery;
      }
    }
    return Finish(stats, rejected, windows, result);
  }

  const MonteCarloValue& value(int slot) const { return values_[slot]; }

 private:
  double* Input(int i) { return buffer_.data() + static_cast<std::size_t>(i) * kStride; }
  double* Output(int k) { return buffer_.data() + static_cast<std::size_t>(kNumInputs + k) * kStride; }
  double* Scratch(int s) {
    return buffer_.data() + static_cast<std::size_t>(kNumInputs + kOutCount + s) * kStride;
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
      // Every rule rejects the values outside an interval: when the block's extremes pass, all do.
      if (!bad(range_[Index(q)].min) && !bad(range_[Index(q)].max)) return;
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

    if (OnePass(n)) return Compact(n, any_bad, reason, rejected);
    double* B = Scratch(0);
    double* T = Scratch(1);
    RailsArrays rails;
    // The vector path leaves the angles to NarrowAtan (narrow_atan.hpp); from given angles θ and α
    // are copies either way.
    rails.theta = narrow_ && apparatus ? nullptr : Output(kOutTheta);
    rails.alpha = narrow_ && apparatus ? nullptr : Output(kOutAlpha);
    rails.phi = narrow_ ? nullptr : Output(kOutPhi);
    rails.tan_theta = B;
    rails.tan_half_alpha = T;
    if (apparatus) {
      RailsFromApparatusBatch(n, L, H, D, p_.convention, rails, o_.kernel);
    } else {
      RailsFromAnglesBatch(n, Input(Index(InputQuantity::kTheta)), Input(Index(InputQuantity::kAlpha)),
                           rails, o_.kernel);
    }
#if defined(__x86_64__) && defined(__GNUC__)
    if (narrow_) {
      double* phi_argument = Scratch(3);
      Bounds bounds[3];
      PhiArgumentAvx2(n, B, T, phi_argument, bounds);
      if (apparatus) {
        Angle(kOutTheta, n, B, 1.0, bounds[0]);
        Angle(kOutAlpha, n, T, 2.0, bounds[1]);
      }
      Angle(kOutPhi, n, phi_argument, 1.0, bounds[2]);
    }
#endif
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

    return Compact(n, any_bad, reason, rejected);
  }

  // Counts the block's rejected trials by reason and compacts the outputs to the valid ones.
  std::size_t Compact(std::size_t n, bool any_bad, const unsigned char* reason, RejectedTrials* rejected) {
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
  // Output `slot` = scale·atan(x) for the block (vector path): by the Taylor polynomial about a
  // centre fixed at the first block whose arguments are all > 0 (their midpoint), of the degree
  // this block's range needs; by libmvec where no degree ≤ NarrowAtan::kMaxDegree suffices. Both
  // depend only on the argument's own values, never on other inputs' draws.
  void Angle(int slot, std::size_t n, const double* x, double scale, Bounds range) {
    const double lo = range.lo, hi = range.hi;
    if (!has_atan_[slot] && lo > 0.0 && hi >= lo && std::isfinite(hi)) {
      atan_[slot] = NarrowAtan(0.5 * (lo + hi));
      has_atan_[slot] = true;
    }
    const int degree = has_atan_[slot] ? atan_[slot].DegreeFor(lo, hi) : 0;
    if (degree > 0) {
      atan_[slot].Evaluate(n, x, scale, Output(slot), degree);
    } else {
      NarrowAtan::Libmvec(n, x, scale, Output(slot));
    }
  }

  // The bounds of an input's values in this block: its fill's range, or its exact value.
  Bounds InputBounds(InputQuantity q) const {
    const int i = Index(q);
    return Uncertain(q) ? Bounds{range_[i].min, range_[i].max} : Bounds{p_.value[i], p_.value[i]};
  }

  // The common case (vector path, apparatus with the horizontal L, sphere or spheroid on line
  // rails) in one pass: LineSpheroidOnePassAvx2. The angles' degrees come from bounds of B, T and
  // φ's argument computed from the inputs' bounds by the same expressions: each is monotone in
  // every input and so are its roundings, so the bounds hold for every computed value. False,
  // with nothing written, where the case or the block does not allow it (the stage kernels then
  // run): a block with draws out of the domain, or arguments too spread for NarrowAtan.
  bool OnePass(std::size_t n) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (!narrow_ || p_.given != UncertainRails::Given::kApparatus || p_.convention != LConvention::kHorizontal ||
        p_.rods || p_.body == BodyKind::kDoubleCone)
      return false;
    const Bounds L = InputBounds(InputQuantity::kL), H = InputBounds(InputQuantity::kH),
                 D = InputBounds(InputQuantity::kD);
    if (!(L.lo > 0.0) || !(H.lo >= 0.0) || !(D.lo > 0.0)) return false;
    Bounds arg[3];
    arg[0] = {H.lo / L.hi, H.hi / L.lo};                  // B = H/L
    arg[1] = {D.lo / (2 * L.hi), D.hi / (2 * L.lo)};      // T = D/(2L)
    arg[2] = {arg[1].lo / std::sqrt(std::fma(arg[0].hi, arg[0].hi, 1.0)),
              arg[1].hi / std::sqrt(std::fma(arg[0].lo, arg[0].lo, 1.0))};  // T/sqrt(1 + B²)
    // One degree for the three angles, the largest any needs (a higher degree only adds terms
    // below the rounding): one compiled pass per degree.
    const int slot[3] = {kOutTheta, kOutAlpha, kOutPhi};
    NarrowAtan atan[3];
    int degree = 0;
    for (int k = 0; k < 3; ++k) {
      if (!has_atan_[slot[k]] && arg[k].lo > 0.0 && std::isfinite(arg[k].hi)) {
        atan_[slot[k]] = NarrowAtan(0.5 * (arg[k].lo + arg[k].hi));
        has_atan_[slot[k]] = true;
      }
      const int d = has_atan_[slot[k]] ? atan_[slot[k]].DegreeFor(arg[k].lo, arg[k].hi) : 0;
      if (d == 0) return false;
      degree = std::max(degree, d);
      atan[k] = atan_[slot[k]];
    }
    const double* across = Input(Index(InputQuantity::kAcross));
    const double* along = p_.body == BodyKind::kSphere ? across : Input(Index(InputQuantity::kAlong));
    double* const out[5] = {Output(kOutTheta), Output(kOutAlpha), Output(kOutPhi), Output(kOutXEq), Output(kOutXMax)};
    LineSpheroidOnePassAvx2(degree, n, Input(Index(InputQuantity::kL)), Input(Index(InputQuantity::kH)),
                            Input(Index(InputQuantity::kD)), across, along, atan, out);
    return true;
#else
    (void)n;
    return false;
#endif
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
      // The window ends' ranks in the pilot (-1: that side stays open), then all four selected.
      std::ptrdiff_t rank[2][2] = {{-1, -1}, {-1, -1}};
      double half[2] = {0.0, 0.0};
      std::vector<std::ptrdiff_t> ranks;
      for (int e = 0; e < 2; ++e) {
        s.window[e] = Window{};
        if (v.empty()) continue;  // every pilot trial rejected: the window keeps everything
        half[e] = kWindowSigmas * std::sqrt(ends[e] * (1.0 - ends[e]) / m);
        const double lo_p = ends[e] - half[e], hi_p = ends[e] + half[e];
        if (lo_p > 0.0) ranks.push_back(rank[e][0] = static_cast<std::ptrdiff_t>(std::floor(lo_p * (m - 1))));
        if (hi_p < 1.0) ranks.push_back(rank[e][1] = static_cast<std::ptrdiff_t>(std::ceil(hi_p * (m - 1))));
      }
      std::sort(ranks.begin(), ranks.end());
      ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
      SelectRanks(v.data(), v.data() + v.size(), ranks.data(), ranks.data() + ranks.size(), v.data());
      for (int e = 0; e < 2; ++e) {
        Window& w = s.window[e];
        if (v.empty()) continue;
        if (rank[e][0] >= 0) w.lo = v[static_cast<std::size_t>(rank[e][0])];
        if (rank[e][1] >= 0) w.hi = v[static_cast<std::size_t>(rank[e][1])];
        w.kept.Reserve(static_cast<std::size_t>(2.5 * half[e] * static_cast<double>(o_.trials)) + 64);
      }
      CountWindows(s.window, v.data(), v.size(), o_.kernel);
      std::vector<double>().swap(v);
    }
  }

  // The windows narrowed to p ± kWindowSigmas·sqrt(p(1 − p)/m) from the m valid trials so far,
  // whose order statistics near the window are known exactly (`below` and the kept values): the
  // new ends are kept values at those ranks, the kept values outside them are dropped (those
  // below counted). Exact like the first windows, with the same margin for the final order
  // statistics, and the later trials keep fewer values: at 10^6 trials about 4 000 per window end
  // instead of 11 000, so that the keeping and the final selection cost less than half as much.
  void NarrowWindows(std::uint64_t m, std::vector<OutputStats>* stats) {
    const double ends[2] = {(1.0 - o_.coverage) / 2, (1.0 + o_.coverage) / 2};
    const double mm = static_cast<double>(m);
    for (OutputStats& s : *stats) {
      if (!s.varies || m < 2) continue;
      for (int e = 0; e < 2; ++e) {
        Window& w = s.window[e];
        const double half = kWindowSigmas * std::sqrt(ends[e] * (1.0 - ends[e]) / mm);
        double lo = w.lo, hi = w.hi;
        // The kept value of 0-based rank g among all m, if the window holds it.
        auto at = [&](double rank, double* end) {
          const double g = rank - static_cast<double>(w.below);
          if (g < 0.0 || g >= static_cast<double>(w.kept.size())) return;
          double* it = w.kept.begin() + static_cast<std::ptrdiff_t>(g);
          std::nth_element(w.kept.begin(), it, w.kept.end());
          *end = *it;
        };
        if (ends[e] - half > 0.0) at(std::floor((ends[e] - half) * (mm - 1)), &lo);
        if (ends[e] + half < 1.0) at(std::ceil((ends[e] + half) * (mm - 1)), &hi);
        double* out = w.kept.begin();
        for (const double* v = w.kept.begin(); v != w.kept.end(); ++v) {
          if (*v < lo) {
            ++w.below;
          } else if (*v <= hi) {
            *out++ = *v;
          }
        }
        w.kept.SetEnd(out);
        w.lo = lo;
        w.hi = hi;
      }
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
  GaussianStream::Range range_[kNumInputs];  // bounds of each uncertain input's current block
  bool narrow_ = false;  // the vector path: angles by NarrowAtan
  NarrowAtan atan_[kOutCount];
  bool has_atan_[kOutCount] = {};
  MonteCarloValue values_[kOutCount];
};

}  // namespace

void MonteCarlo(const Problem& p, const PropagationOptions& options, PropagationResult* result,
                MonteCarloValue (&values)[kOutCount]) {
  MonteCarloRun mc(p, options);
  if (!mc.Run(/*store_all=*/false, result)) {
    // A window missed its order statistic (improbable by design): redo the same trials and
    // select exactly from all of them.
    ++result->window_reruns;
    mc.Run(/*store_all=*/true, result);
  }
  for (int k = 0; k < kOutCount; ++k)
    if (HasOutput(p.body, k)) values[k] = mc.value(k);
}

}  // namespace uphill::internal
