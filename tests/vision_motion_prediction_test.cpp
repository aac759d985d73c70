// The tracker's motion prediction (src/vision/internal/motion_prediction.hpp): the polynomial
// through the last centres, and the time at which the centre's own row is read under a rolling
// shutter. Truth: closed forms. A motion of constant acceleration sampled at uneven times is
// recovered exactly. The row-time fixed point is checked against the root of the quadratic that
// t = frame_t + row(c(t))·δ becomes when the row is linear in the centre, solved here with the
// quadratic formula. The sizes are the phone clip's (1080 rows read over 25 ms, the ball 64 px
// per frame at 30 fps).
#include <gtest/gtest.h>

#include <cmath>

#include "internal/motion_prediction.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;

// A motion of constant acceleration, m and s.
struct Parabola {
  Vector2d c0{0.70, 0.19}, v0{-0.9, -0.23}, a{-1.6, -0.42};
  Vector2d At(double t) const { return c0 + v0 * t + 0.5 * a * t * t; }
};

std::vector<TimedCentre> Sampled(const Parabola& p, const std::vector<double>& times) {
  std::vector<TimedCentre> out;
  for (double t : times) out.push_back({t, p.At(t)});
  return out;
}

TEST(MotionFit, RecoversAConstantAccelerationFromUnevenSamples) {
  const Parabola p;
  const auto fit = MotionFit::Through(Sampled(p, {0.40, 0.4334, 0.4671, 0.5003, 0.5339, 0.5672}));
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->degree(), 2);
  const double t = 0.61;
  const MotionState s = fit->At(t);
  EXPECT_LT((s.centre - p.At(t)).norm(), 1e-12);
  EXPECT_LT((s.velocity - (p.v0 + p.a * t)).norm(), 1e-10);
  EXPECT_LT((s.acceleration - p.a).norm(), 1e-8);
}

TEST(MotionFit, ALineThroughTwoOrThreeSamplesAndTheCentreFromOne) {
  const Parabola line{{0.5, 0.2}, {0.3, -0.1}, {0, 0}};
  for (const std::vector<double>& times : {std::vector<double>{0.1, 0.2}, std::vector<double>{0.1, 0.2, 0.35}}) {
    const auto fit = MotionFit::Through(Sampled(line, times));
    ASSERT_TRUE(fit.has_value());
    EXPECT_EQ(fit->degree(), 1);
    EXPECT_LT((fit->At(0.5).centre - line.At(0.5)).norm(), 1e-13);
    EXPECT_EQ(fit->At(0.5).acceleration, Vector2d::Zero());
  }
  const auto one = MotionFit::Through(Sampled(line, {0.1}));
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->degree(), 0);
  EXPECT_EQ(one->At(0.9).centre, line.At(0.1));
  EXPECT_EQ(one->At(0.9).velocity, Vector2d::Zero());
  EXPECT_FALSE(MotionFit::Through({}).has_value());
}

TEST(MotionFit, FourSamplesGiveTheParabolaThroughThem) {
  const Parabola p;
  const auto fit = MotionFit::Through(Sampled(p, {0.40, 0.4334, 0.4671, 0.5003}));
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->degree(), 2);
  EXPECT_LT((fit->At(0.55).centre - p.At(0.55)).norm(), 1e-12);
  EXPECT_LT((fit->At(0.55).acceleration - p.a).norm(), 1e-7);
}

TEST(MotionFit, TheCentreAtTheTimeItsOwnRowIsRead) {
  const Parabola p;
  const double frame_t = 0.6, delay = 0.025 / 1080;
  // Image rows linear in z: row = r0 + k·z, k in px per m (1000 px per m: the ball moves 1.9 m/s,
  // 64 px per frame, and its centre lies near row 500, read 11.7 ms into the frame).
  const double r0 = 480, k = -1000;
  const auto row = [&](const Vector2d& c) { return r0 + k * c.y(); };
  const auto fit = MotionFit::Through(Sampled(p, {0.4333, 0.4667, 0.5, 0.5333, 0.5667}));
  ASSERT_TRUE(fit.has_value());
  const MotionState s = fit->AtOwnRow(frame_t, delay, row);
  // t = frame_t + δ·(r0 + k·(z0 + vz·t + ½·az·t²)), i.e. qa·t² + qb·t + qc = 0 with the
  // coefficients below; the root near frame_t, in the form that does not cancel (qa is small).
  const double qa = 0.5 * delay * k * p.a.y(), qb = delay * k * p.v0.y() - 1,
               qc = frame_t + delay * (r0 + k * p.c0.y());
  const double root = 2 * qc / (-qb + std::sqrt(qb * qb - 4 * qa * qc));
  ASSERT_NEAR(root, frame_t + delay * row(p.At(frame_t)), 2e-4);  // the root meant, not the far one
  // The iteration stops once a step moves the time by < 1e-10 s; its error is then 0.01 of that.
  EXPECT_NEAR(s.t, root, 1e-11);
  EXPECT_LT((s.centre - p.At(root)).norm(), 1e-10);
  EXPECT_LT((s.velocity - (p.v0 + p.a * root)).norm(), 1e-9);
  // The frame time's prediction shifted by v·τ0, τ0 = row·δ read off it, misses by exactly
  // v·(τ0 − τ) − ½·a·τ² for a parabola (τ = root − frame_t): 0.37 mm here, 0.37 px.
  const MotionState at_frame = fit->At(frame_t);
  const double tau0 = row(at_frame.centre) * delay, tau = root - frame_t;
  const Vector2d shifted = at_frame.centre + at_frame.velocity * tau0;
  const Vector2d miss = at_frame.velocity * (tau0 - tau) - 0.5 * p.a * tau * tau;
  EXPECT_LT((shifted - p.At(root) - miss).norm(), 1e-12);
  EXPECT_GT(miss.norm(), 3e-4);
  // Without a rolling shutter: the frame's time.
  EXPECT_EQ(fit->AtOwnRow(frame_t, 0, row).t, frame_t);
}

}  // namespace
}  // namespace uphill::internal
