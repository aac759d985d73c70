#include "smeared_outline.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace uphill::internal {
namespace {

using Eigen::Vector3d;

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
// Beyond this many standard deviations Φ is taken as 0 or 1 and φ as 0: Φ(−6) = 9.9e-10 and
// φ(6) = 6.1e-9, so a coverage errs by at most 1e-9 (the fit reads it to about 1e-8, the noise
// to about 1e-2), and a node that far from the edge costs no arithmetic.
constexpr double kSaturated = 6.0;

// Φ and φ on a grid of step 1/128 over ±kSaturated, computed once with erfc and exp, and read
// back by cubic Hermite interpolation (the derivatives are known: Φ' = φ, φ' = −u·φ). The
// interpolation's error is h⁴/384 times the fourth derivative's maximum: below 2e-11 for both
// (tests/vision_smeared_outline_test.cpp compares with erfc and exp), far below the 1e-8 the
// coverage is used to; it saves the erfc and the exp of every node of every sample.
class NormalTable {
 public:
  static constexpr double kStep = 1.0 / 128;
  static constexpr int kNodes = static_cast<int>(2 * kSaturated / kStep) + 2;
  NormalTable() {
    for (int i = 0; i < kNodes; ++i) {
      const double u = -kSaturated + i * kStep;
      cdf_[i] = 0.5 * std::erfc(-u * kInvSqrt2);
      pdf_[i] = kInvSqrt2Pi * std::exp(-0.5 * u * u);
    }
  }
  // Φ(u) and φ(u) for |u| ≤ kSaturated.
  void At(double u, double* cdf, double* pdf) const {
    const double x = (u + kSaturated) / kStep;
    const int i = std::min(static_cast<int>(x), kNodes - 2);
    const double t = x - i, h = kStep;
    const double u0 = -kSaturated + i * kStep, u1 = u0 + kStep;
    // Hermite basis on [0, 1].
    const double t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
    *cdf = h00 * cdf_[i] + h10 * h * pdf_[i] + h01 * cdf_[i + 1] + h11 * h * pdf_[i + 1];
    *pdf = h00 * pdf_[i] - h10 * h * u0 * pdf_[i] + h01 * pdf_[i + 1] - h11 * h * u1 * pdf_[i + 1];
  }

 private:
  double cdf_[kNodes], pdf_[kNodes];
};

// Built at start-up rather than on first use, so that reading it costs no guard per node.
const NormalTable kNormal;

// Φ, φ and Ψ at one node (most samples of a ray lie in the saturated tails, away from the edge).
struct NodeCdf {
  double u, cdf, pdf, integrated;
  explicit NodeCdf(double x) : u(x) {
    if (x > kSaturated) cdf = 1, pdf = 0;
    else if (x < -kSaturated) cdf = 0, pdf = 0;
    else kNormal.At(x, &cdf, &pdf);
    integrated = x * cdf + pdf;  // Ψ(u) = ∫_{−∞}^{u} Φ = u·Φ(u) + φ(u)
  }
};

// The angle between two unit vectors from the squared length q of their chord: θ = 2·asin(√q/2).
// The body subtends a small angle, so the directions the coverage meets are mostly within 0.1 rad
// of its centre's: there the odd series of 2·asin(c/2) in the chord c to c¹¹ errs by less than
// 4.3e-6·c¹³ < 1e-18 rad (its terms are positive; the next is 4.24e-6·c¹³), and costs a few
// multiplications and no division (the chord of two unit vectors is as accurate as their
// difference); elsewhere asin. The interpolated nodes of a rolling shutter's rows are unit to
// about 2e-7 (the square of their span over 8), which moves the angle by about β·1e-7: 3e-6 px.
double AngleOfChord(double q, double chord) {
  if (!(q <= 0.01)) return 2 * std::asin(std::min(1.0, 0.5 * chord));
  return chord * (1 + q * (1.0 / 24 + q * (3.0 / 640 + q * (5.0 / 7168 + q * (35.0 / 294912 + q * (63.0 / 2883584))))));
}

// asin(x) for x in [0, 1): the body's half angle, mostly below 0.1 rad, where the series to x¹¹
// errs by less than 2e-15 rad (its next term, 231/13312·x¹³); elsewhere std::asin.
double Asin(double x) {
  if (!(x < 0.1)) return std::asin(x);
  const double x2 = x * x;
  return x * (1 + x2 * (1.0 / 6 + x2 * (3.0 / 40 + x2 * (5.0 / 112 + x2 * (35.0 / 1152 + x2 * (63.0 / 2816))))));
}

// Mean of Φ over u linear from a.u to b.u, and its derivatives with respect to a.u and b.u (each
// node's Φ and Ψ computed once, shared by the pieces either side of it).
double MeanCdf(const NodeCdf& a, const NodeCdf& b, double* d0, double* d1) {
  if (a.pdf == 0 && b.pdf == 0 && a.cdf == b.cdf) {
    *d0 = *d1 = 0;
    return a.cdf;
  }
  const double h = b.u - a.u;
  if (std::abs(h) < 1e-4) {
    // The mean is Φ(a) + φ(a)·h/2 to O(h²·|u|·φ) < 1e-8 (a body at rest: h = 0, exact).
    *d0 = *d1 = 0.5 * a.pdf;
    return a.cdf + 0.5 * a.pdf * h;
  }
  const double mean = (b.integrated - a.integrated) / h;
  *d1 = (b.cdf - mean) / h;
  *d0 = (mean - a.cdf) / h;
  return mean;
}

}  // namespace

int SmearPieces(double blur_px, double radius_px) {
  // Linear pieces of length h (px of motion) err by h²/(8·radius) where the smeared outline
  // turns; h ≤ sqrt(0.16·radius) keeps that at 0.02 px.
  const double h = std::sqrt(0.16 * std::max(radius_px, 1.0));
  return std::clamp(static_cast<int>(std::ceil(std::abs(blur_px) / h)), 1, kMostPieces);
}

SmearNodes::SmearNodes(const SmearedBody& body, const double* p, const Eigen::Vector2d& offset, int pieces,
                       const Eigen::Vector2d& bend)
    : body_(body), shift_(p[kEdgeShift]) {
  const int m = std::clamp(pieces, 1, kMostPieces);
  count_ = m + 1;
  reach_[0] = 0;
  for (int n = 0; n <= m; ++n) {
    Node& node = nodes_[n];
    node.tau = -0.5 + static_cast<double>(n) / m;
    const double tau2 = node.tau * node.tau;
    const Vector3d v(p[kCentreX] + offset.x() + node.tau * p[kSmearX] + tau2 * bend.x() - body.eye.x(), -body.eye.y(),
                     p[kCentreZ] + offset.y() + node.tau * p[kSmearZ] + tau2 * bend.y() - body.eye.z());
    node.norm = v.norm();
    node.w = v / node.norm;
    const double sin_b = std::min(body.a / node.norm, 1.0 - 1e-12);
    node.beta = Asin(sin_b);
    node.tan_beta = sin_b / std::sqrt(1 - sin_b * sin_b);
    if (n > 0) {
      // |δ_n − δ_{n−1}| ≤ p·(θ(w_{n−1}, w_n) + |β_n − β_{n−1}|) by the triangle inequality of
      // angles. The angle from its chord c: θ = 2·asin(c/2) = c + c³/24 + … ≤ c·(1 + c²/8) for
      // c ≤ 1 (successive nodes are far closer: c is the smear's angle over the pieces); 1e-9 of
      // it spares rounding.
      const Node& last = nodes_[n - 1];
      const double chord = (node.w - last.w).norm();
      const double angle = chord <= 1 ? chord * (1 + chord * chord / 8) : 2 * std::asin(std::min(1.0, chord / 2));
      const double step = angle + std::abs(node.beta - last.beta);
      reach_[n] = reach_[n - 1] + step * body.px_per_rad * (1 + 1e-9);
    }
  }
}

SmearNodes::SmearNodes(const SmearNodes& a, const SmearNodes& b, double t)
    : body_(a.body_), shift_(a.shift_), count_(a.count_) {
  reach_[0] = 0;  // before the loop: node 1's reach adds to it
  for (int n = 0; n < count_; ++n) {
    const Node &na = a.nodes_[n], &nb = b.nodes_[n];
    Node& node = nodes_[n];
    node.w = na.w + t * (nb.w - na.w);
    node.norm = na.norm + t * (nb.norm - na.norm);
    node.beta = na.beta + t * (nb.beta - na.beta);
    node.tan_beta = na.tan_beta + t * (nb.tan_beta - na.tan_beta);
    node.tau = na.tau;
    if (n > 0) {
      const double step = std::max(a.reach_[n] - a.reach_[n - 1], b.reach_[n] - b.reach_[n - 1]);
      reach_[n] = reach_[n - 1] + step * (1 + 1e-3);
    }
  }
}

double SmearNodes::DistanceAtMiddle(const Vector3d& d) const {
  // Linear between the nodes either side of τ = 0 (exact for an odd count of pieces' midpoint
  // up to the bend of δ, which is below rounding for the use made of it: windows and masks).
  const size_t m = static_cast<size_t>(count_) - 1, lo = m / 2, hi = (m + 1) / 2;
  auto delta = [&](const Node& n) {
    return (std::atan2(d.cross(n.w).norm(), d.dot(n.w)) - n.beta) * body_.px_per_rad - shift_;
  };
  return 0.5 * (delta(nodes_[lo]) + delta(nodes_[hi]));
}

double SmearNodes::Coverage(const Vector3d& d, SmearGradient* grad, BodyShading::Basis* shade) const {
  const double p = body_.px_per_rad, sigma = body_.sigma_px;
  const size_t count = static_cast<size_t>(count_);
  // u_n = −δ_n/σ at the nodes that can pull. The others are skipped, marked by a u beyond the
  // saturation: δ moves by at most reach_n − reach_k from node k to node n (reach_), so a
  // node closer than that to an exact node k far in a tail lies in the same tail, with Φ = 0 or 1
  // and φ = 0, as do the pieces between such nodes (MeanCdf's constant case: exact, no pull).
  constexpr size_t kMost = kMostPieces + 1;
  double u[kMost], chord2[kMost], chord[kMost];
  // px: beyond it Φ is saturated (with 1e-6 px to spare for rounding).
  const double band = kSaturated * sigma + 1e-6, inv_sigma = 1 / sigma;
  const auto evaluate = [&](size_t n) {
    const Node& node = nodes_[n];
    chord2[n] = (d - node.w).squaredNorm();
    chord[n] = std::sqrt(chord2[n]);
    u[n] = -((AngleOfChord(chord2[n], chord[n]) - node.beta) * p - shift_) * inv_sigma;
  };
  evaluate(0);
  for (size_t k = 0;;) {
    // Nodes n > k with reach_n − reach_k below |δ_k| − band are in δ_k's tail.
    const double room = std::abs(u[k]) * sigma - band;
    const double from = reach_[k], tail = u[k] > 0 ? kSaturated + 1 : -kSaturated - 1;
    size_t j = k + 1;
    for (; j < count && reach_[j] - from < room; ++j) u[j] = tail;
    if (j == count) break;
    evaluate(j);
    // The piece (j − 1, j) needs both ends where node j is not in the same tail as the skipped.
    if (j - 1 > k && !(std::abs(u[j]) > kSaturated && (u[j] > 0) == (u[k] > 0))) evaluate(j - 1);
    k = j;
  }
  // The pieces: one with both ends in the same saturated tail is Φ = 0 or 1 throughout, with no
  // pull (MeanCdf's constant case, taken here without forming its nodes' Φ); the others ("live")
  // are integrated, and their nodes listed for the gradient.
  const size_t pieces = count - 1;
  double coverage = 0;
  double du[kMost];
  double cdf[kMost];  // Φ at the live pieces' nodes, for the shading's weights
  size_t live[kMost], lives = 0;
  NodeCdf left(0.0);
  bool left_known = false;  // left is node j's: the piece before it was live
  for (size_t j = 0; j < pieces; ++j) {
    const double a = u[j], b = u[j + 1];
    if ((a > kSaturated && b > kSaturated) || (a < -kSaturated && b < -kSaturated)) {
      coverage += a > 0 ? 1.0 : 0.0;
      left_known = false;
      continue;
    }
    if (!left_known) {
      left = NodeCdf(a);
      cdf[j] = left.cdf;
      du[j] = 0;
      live[lives++] = j;
    }
    const NodeCdf right(b);
    cdf[j + 1] = right.cdf;
    du[j + 1] = 0;
    live[lives++] = j + 1;
    double d0, d1;
    coverage += MeanCdf(left, right, &d0, &d1);
    du[j] += d0;
    du[j + 1] += d1;
    left = right;
    left_known = true;
  }
  coverage /= static_cast<double>(pieces);
  if (shade) {
    shade->setZero();
    if (body_.shading) {
      double weight = 0;
      // A node not saturated ends a live piece, whose Φ the loop above kept.
      for (size_t n = 0; n < count; ++n) {
        const double phi = u[n] > kSaturated ? 1.0 : u[n] < -kSaturated ? 0.0 : cdf[n];
        if (phi < 1e-6) continue;
        const double w = phi * (n == 0 || n == pieces ? 0.5 : 1.0);
        const Node& node = nodes_[n];
        *shade += w * body_.shading->LearntBasisAt(d, node.w * node.norm, body_.a);
        weight += w;
      }
      if (weight > 0) *shade /= weight;
    }
  }
  if (grad) {
    grad->fill(0.0);
    for (size_t i = 0; i < lives; ++i) {
      const size_t n = live[i];
      if (du[n] == 0) continue;  // no pull
      // ∂c/∂δ_n = ∂c/∂u_n · (−1/σ); ∂δ_n/∂(x, z) from ∂θ/∂v = −(d − cosθ·ŵ)/(|v|·sinθ) and
      // ∂β/∂v = −tanβ·ŵ/|v| (the same for D, scaled by τ_n).
      // Of unit vectors with chord c: cos θ = 1 − c²/2, sin θ = c·√(1 − c²/4).
      const Node& node = nodes_[n];
      const double w = -du[n] / (static_cast<double>(pieces) * sigma);
      const double cos_t = 1 - 0.5 * chord2[n], sin_t = chord[n] * std::sqrt(std::max(0.0, 1 - 0.25 * chord2[n]));
      const double k = 1.0 / (node.norm * std::max(sin_t, 1e-12));
      const Vector3d g = (-(d - cos_t * node.w) * k + node.tan_beta / node.norm * node.w) * p;
      (*grad)[kCentreX] += w * g.x();
      (*grad)[kCentreZ] += w * g.z();
      (*grad)[kSmearX] += w * g.x() * node.tau;
      (*grad)[kSmearZ] += w * g.z() * node.tau;
      (*grad)[kEdgeShift] += w * -1.0;
    }
  }
  return coverage;
}

}  // namespace uphill::internal
