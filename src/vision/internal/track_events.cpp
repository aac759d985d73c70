#include "track_events.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace uphill::internal {

std::optional<int> FirstDeparture(const std::vector<double>& v, bool backward, double band, int confirm,
                                  int reference) {
  const int n = static_cast<int>(v.size());
  const auto at = [&](int j) { return v[backward ? n - 1 - j : j]; };
  std::vector<double> window;
  double m = at(0);
  for (int j = 1; j < n; ++j) {
    if (j <= reference) {
      window.clear();
      for (int k = 0; k < j; ++k) window.push_back(at(k));
      m = Median(window);
    }
    const double side = at(j) - m;
    if (std::abs(side) <= band || j + confirm > n) continue;
    bool confirmed = true;
    for (int c = 1; c < confirm && confirmed; ++c) {
      const double d = at(j + c) - m;
      confirmed = std::abs(d) > band && (d > 0) == (side > 0);
    }
    if (confirmed) return j;
  }
  return std::nullopt;
}

std::optional<TrackEvent> ParabolaVertex(const Series& s, const std::vector<double>& smooth, int centre, double reach,
                                         int sign, double sigma, int lo_limit, int hi_limit) {
  int lo = centre, hi = centre;
  const auto near = [&](int i) { return std::abs(smooth[i] - smooth[centre]) <= reach; };
  while (lo - 1 >= lo_limit && centre - lo < 40 && (near(lo - 1) || centre - lo < 2)) --lo;
  while (hi + 1 <= hi_limit && hi - centre < 40 && (near(hi + 1) || hi - centre < 2)) ++hi;
  int n = hi - lo + 1;
  if (n < 5 || centre - lo < 2 || hi - centre < 2) return std::nullopt;
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (int i = lo; i <= hi; ++i) {
    const double tau = s.t[i] - s.t[centre];
    a.row(i - lo) << 1.0, tau, tau * tau;
    b(i - lo) = s.x[i];
  }
  Eigen::Vector3d c = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd residual = a * c - b;
  for (int k = 0; k < residual.size(); ++k)
    if (std::abs(residual(k)) > 4 * sigma) {  // a zero row does not count
      a.row(k).setZero();
      b(k) = 0;
      --n;
    }
  if (n < 5) return std::nullopt;
  c = a.colPivHouseholderQr().solve(b);
  if (!(c(2) * sign < 0)) return std::nullopt;
  const Eigen::Matrix3d cov = sigma * sigma * (a.transpose() * a).inverse();
  const double tau = -c(1) / (2 * c(2));
  if (!(tau >= s.t[lo] - s.t[centre] && tau <= s.t[hi] - s.t[centre])) return std::nullopt;
  const Eigen::Vector3d dtau(0.0, -1.0 / (2 * c(2)), c(1) / (2 * c(2) * c(2)));
  const Eigen::Vector3d dx(1.0, -c(1) / (2 * c(2)), c(1) * c(1) / (4 * c(2) * c(2)));
  TrackEvent e;
  e.kind = "turning point";
  e.t = {s.t[centre] + tau, std::sqrt(dtau.dot(cov * dtau))};
  e.x = {c(0) - c(1) * c(1) / (4 * c(2)), std::sqrt(dx.dot(cov * dx))};
  e.method = "vertex of a parabola through " + std::to_string(n) + " frames";
  return e;
}

std::optional<RestFit> FitRest(const Series& s, int begin, int end, int min_frames) {
  const int n = end - begin;
  if (n < 4) return std::nullopt;
  std::optional<RestFit> best;
  double best_rss = std::numeric_limits<double>::infinity();
  // The approach lies at the start of the tail: 200 candidates keep an hour of rest cheap.
  const int last = std::min(end - std::max(min_frames / 2, 2), begin + 200);
  for (int r = begin; r <= last; ++r) {
    Eigen::MatrixXd a(n, 2);
    Eigen::VectorXd b(n);
    for (int i = begin; i < end; ++i) {
      const double before = std::max(s.t[r] - s.t[i], 0.0);
      a.row(i - begin) << 1.0, before * before;
      b(i - begin) = s.x[i];
    }
    if (r == begin) a.col(1).setZero();  // no approach: the plain mean
    const auto qr = a.colPivHouseholderQr();
    const Eigen::Vector2d c = qr.solve(b);
    const double rss = (a * c - b).squaredNorm();
    if (!(rss < best_rss)) continue;
    best_rss = rss;
    const double scatter = std::sqrt(rss / std::max(n - 3, 1));
    Eigen::Matrix2d ata = a.transpose() * a;
    const double var = r == begin ? 1.0 / n : ata.inverse()(0, 0);
    best = RestFit{{c(0), scatter * std::sqrt(var)}, s.t[r], scatter, end - r};
  }
  return best;
}

}  // namespace uphill::internal
