#include "body_shading.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "linear_light.hpp"
#include "outline_fit.hpp"

namespace uphill::internal {
namespace {

constexpr double kReliable = 0.8;     // share of the radius within which a view shows the body alone
const double kReliableCos = std::sqrt(1 - kReliable * kReliable);
constexpr double kGridStep = 0.08;    // of the radius, between the samples of a view
constexpr double kMaxMisfit = 0.08;   // RMS relative residual of a body whose colour follows its normal
constexpr double kMinInliers = 0.85;  // share of the samples the quadratic explains
constexpr double kFloor = 0.02;       // the least relative colour read back
constexpr int kPasses = 8;            // of the robust fit
constexpr double kCutBright = 2, kCutDark = 3.5;  // robust deviations

}  // namespace

BodyShading::Basis BodyShading::OfNormal(const Eigen::Vector3d& n) {
  Basis basis;
  basis << 1, n.x(), n.y(), n.z(), n.x() * n.y(), n.y() * n.z(), n.x() * n.z(), n.x() * n.x() - n.y() * n.y(),
      3 * n.z() * n.z() - 1;
  return basis;
}

BodyShading::Basis BodyShading::LearntBasisAt(const Eigen::Vector3d& d, const Eigen::Vector3d& v, double a) const {
  const double b = d.dot(v), disc = b * b - v.squaredNorm() + a * a;
  // The surface point the ray meets first (its distance from the centre is a); a ray that misses
  // reads the limb point nearest to it.
  Eigen::Vector3d n = disc >= 0 ? Eigen::Vector3d(((b - std::sqrt(disc)) * d - v) / a) : (b * d - v).normalized();
  // Beyond the part of the disc the views show (sin of the angle to the eye above kReliable) the
  // quadratic is an extrapolation: the normal at kReliable in the same direction is read instead.
  const double towards_eye = -n.dot(d);
  if (towards_eye < kReliableCos) {
    const Eigen::Vector3d across = (n + towards_eye * d).normalized();
    n = kReliable * across - kReliableCos * d;
  }
  if (s_ == 1) return OfNormal(n);
  n.y() *= s_;  // back from the scaled space: normals scale by the inverse transpose
  return OfNormal(n.normalized());
}

BodyShading BodyShading::Turned(const Eigen::Vector3d& omega) const {
  BodyShading turned(*this);
  const double angle = omega.norm();
  if (!(angle > 0)) return turned;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  // The colour at normal n is the learnt colour at turnᵀ·n: the turned colours at 16 normals
  // spread over the sphere, whose bases span the 9, give the coefficients on the unturned basis
  // by least squares (exact: the turned colour is itself a quadratic in n).
  static const auto normals = [] {
    std::array<Eigen::Vector3d, 16> n;
    for (int k = 0; k < 16; ++k) {
      const double z = 1 - (2 * k + 1) / 16.0, r = std::sqrt(1 - z * z), phi = k * 2.399963229728653;
      n[k] = Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
    }
    return n;
  }();
  static const Eigen::Matrix<double, 9, 16> solve = [] {
    Eigen::Matrix<double, 16, 9> p;
    for (int k = 0; k < 16; ++k) p.row(k) = OfNormal(normals[k]).transpose();
    return Eigen::Matrix<double, 9, 16>((p.transpose() * p).ldlt().solve(p.transpose()));
  }();
  Eigen::Matrix<double, 16, 3> colours;
  for (int k = 0; k < 16; ++k) colours.row(k) = OfNormal(turn.transpose() * normals[k]).transpose() * coefficients_;
  turned.colours_ = (solve * colours).transpose();
  return turned;
}

BodyShading BodyShading::LitFrom(const Eigen::Vector3d& centre, double inverse_distance) const {
  const Eigen::Vector3d light = Eigen::Vector3d::UnitZ();  // overhead
  const Eigen::Vector3d seen = light - inverse_distance * (centre - learnt_at_);
  if (seen.norm() < 1e-9) return *this;
  // The rotation taking the light's direction from where the shading was learnt to where it is
  // seen from now (the shortest one).
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(light, seen);
  const Eigen::AngleAxisd turn(q);
  return Turned(turn.angle() * turn.axis());
}

cv::Vec3d BodyShading::FromBasis(const Basis& basis) const {
  if (basis(0) == 0) return cv::Vec3d(1, 1, 1);  // the constant term of any surface point is 1
  const Eigen::Vector3d c = colours_ * basis;
  return cv::Vec3d(std::max(c.x(), kFloor), std::max(c.y(), kFloor), std::max(c.z(), kFloor));
}

cv::Vec3d BodyShading::At(const Eigen::Vector3d& d, const Eigen::Vector3d& v, double a) const {
  return FromBasis(LearntBasisAt(d, v, a));
}

void BodyShading::Learn(const cv::Mat& bgr, const std::array<float, 256>& table, const OutlineGeometry& g, double x,
                        double z) {
  if (views_ >= kViews) return;
  const Eigen::Vector3d v = Eigen::Vector3d(x, 0, z) - g.eye_s;
  const Eigen::Vector2d centre = g.Project(x, z);
  const double radius_px = g.a * g.cal.camera.fx / v.norm();
  std::vector<Eigen::Vector2d> pixels;
  for (double gy = -kReliable; gy <= kReliable; gy += kGridStep)
    for (double gx = -kReliable; gx <= kReliable; gx += kGridStep) {
      if (gx * gx + gy * gy > kReliable * kReliable) continue;
      const Eigen::Vector2d p = centre + radius_px * Eigen::Vector2d(gx, gy);
      if (!(p.x() >= 1 && p.y() >= 1 && p.x() < bgr.cols - 2 && p.y() < bgr.rows - 2)) continue;
      if (g.occluder && g.occluder->at<std::uint8_t>(static_cast<int>(p.y() + 0.5), static_cast<int>(p.x() + 0.5)))
        continue;
      pixels.push_back(p);
    }
  if (pixels.size() < 40) return;  // too little of the body in view
  const std::vector<Eigen::Vector2d> normalised = UndistortPixels(g.cal.camera, pixels);
  std::vector<std::pair<Basis, cv::Vec3d>> view;
  cv::Vec3d mean(0, 0, 0);
  for (size_t k = 0; k < pixels.size(); ++k) {
    Eigen::Vector3d d = g.to_apparatus * Eigen::Vector3d(normalised[k].x(), normalised[k].y(), 1.0);
    d.y() *= g.s;
    const cv::Vec3d colour(SampleLinear(bgr, table, pixels[k].x(), pixels[k].y()));
    view.emplace_back(LearntBasisAt(d.normalized(), v, g.a), colour);
    mean += colour;
  }
  mean /= static_cast<double>(view.size());
  for (int ch = 0; ch < 3; ++ch)
    if (!(mean[ch] > 1e-4)) return;  // a channel the body does not reflect: nothing to learn
  colour_ += mean / kViews;
  learnt_at_ += Eigen::Vector3d(x, 0, z) / kViews;
  for (auto& [basis, colour] : view) {
    for (int ch = 0; ch < 3; ++ch) colour[ch] /= mean[ch];
    samples_.emplace_back(basis, colour);
  }
  if (++views_ < kViews) return;

  // Least squares, then again without the samples more than 3 robust deviations off (the
  // highlight, compression blocks).
  std::vector<char> inlier(samples_.size(), 1);
  std::vector<double> error(samples_.size());
  std::vector<char> brighter(samples_.size());
  for (int pass = 0; pass < kPasses; ++pass) {
    Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
    Eigen::Matrix<double, 9, 3> rhs = Eigen::Matrix<double, 9, 3>::Zero();
    for (size_t k = 0; k < samples_.size(); ++k) {
      if (!inlier[k]) continue;
      const auto& [basis, colour] = samples_[k];
      normal += basis * basis.transpose();
      rhs += basis * Eigen::RowVector3d(colour[0], colour[1], colour[2]);
    }
    normal.diagonal().array() += 1e-9 * normal.trace();
    coefficients_ = normal.ldlt().solve(rhs);
    for (size_t k = 0; k < samples_.size(); ++k) {
      const Eigen::RowVector3d fitted = samples_[k].first.transpose() * coefficients_;
      const cv::Vec3d& c = samples_[k].second;
      // In proportion to the body's colour: a channel it barely reflects is mostly noise.
      double e2 = 0;
      for (int ch = 0; ch < 3; ++ch) e2 += std::pow((c[ch] - fitted(ch)) * colour_[ch], 2);
      error[k] = std::sqrt(e2) / cv::norm(colour_);
      brighter[k] = (c - cv::Vec3d(fitted(0), fitted(1), fitted(2))).dot(colour_) > 0;
    }
    std::vector<double> sorted = error;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double sigma = 1.4826 * sorted[sorted.size() / 2] + 1e-3;
    // A highlight only adds light, and its shoulders pull the quadratic up: samples brighter than
    // the fit are cut closer than darker ones.
    for (size_t k = 0; k < samples_.size(); ++k) inlier[k] = error[k] <= (brighter[k] ? kCutBright : kCutDark) * sigma;
  }
  double sum = 0;
  size_t count = 0;
  for (size_t k = 0; k < samples_.size(); ++k)
    if (inlier[k]) sum += error[k] * error[k], ++count;
  misfit_ = std::sqrt(sum / std::max<size_t>(count, 1));
  colours_ = coefficients_.transpose();
  ready_ = coefficients_.allFinite() && misfit_ <= kMaxMisfit && count >= kMinInliers * samples_.size();
  samples_.clear();
  samples_.shrink_to_fit();
}

}  // namespace uphill::internal
