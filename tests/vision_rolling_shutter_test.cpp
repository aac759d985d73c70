// The rolling shutter in the full model's fit (src/vision/internal/outline_fit.hpp), and the fit's
// convergence on the same picture: a ball moving fast under a rolling shutter, each row exposed
// for E starting (row − reference row)·δ after the reference row, and the row delay δ that the
// fit's rays prefer (FitRequest::estimate_row_delay).
//
// Truth: the picture is rendered here by brute force, independently of the smear model: every
// pixel's viewing ray (UndistortPixels) is tested against the sphere at 64 instants spread evenly
// over that pixel's row's exposure, along the true straight motion, and the pixel is the mean of
// body and background over those instants, written as 8-bit linear light. The ball is one flat
// colour on a plain background (no shading, no noise but the quantisation), so that what is
// tested is the shear and its timing alone.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <vector>

#include "internal/background_model.hpp"
#include "internal/outline_fit.hpp"
#include "internal/row_delay_settle.hpp"
#include "outline_geometry_support.hpp"
#include "vision/camera.hpp"

namespace uphill::internal {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kRadius = 0.0127;     // m: the 1-inch ball of the fast clips
constexpr double kFps = 30, kExposure = 0.5 / kFps;
constexpr int kWidth = 640, kHeight = 480;  // TestOutlineGeometry's camera
const Vector3d kCentre(0.40, 0, 0.10);  // m, at the reference row's mid-exposure
const Vector2d kVelocity(-1.2, -0.3);   // m/s in (x, z): about 40 px per frame

OutlineGeometry Geometry(const cv::Mat* occluder) {
  OutlineGeometry g = TestOutlineGeometry(kRadius);
  g.occluder = occluder;
  return g;
}

constexpr double kBody = 0.10, kBack = 0.60;  // linear light, all channels

// The frame: rows exposed from (row − reference_row)·readout/kHeight − E/2 to the same + E/2
// after the reference time, the ball at kCentre + kVelocity·t.
cv::Mat Render(const OutlineGeometry& g, double reference_row, double readout) {
  cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar::all(std::lround(255 * kBack)));
  const Vector2d c = g.Project(kCentre.x(), kCentre.z());
  std::vector<Vector2d> raw;
  for (int v = static_cast<int>(c.y()) - 45; v <= c.y() + 45; ++v)
    for (int u = static_cast<int>(c.x()) - 70; u <= c.x() + 70; ++u) raw.emplace_back(u, v);
  const std::vector<Vector2d> rays = UndistortPixels(g.cal.camera, raw);
  constexpr int kInstants = 64;
  for (size_t k = 0; k < raw.size(); ++k) {
    const Vector3d d = (g.to_apparatus * Vector3d(rays[k].x(), rays[k].y(), 1)).normalized();
    const double row_time = (raw[k].y() - reference_row) * readout / kHeight;
    int inside = 0;
    for (int i = 0; i < kInstants; ++i) {
      const double t = row_time + ((i + 0.5) / kInstants - 0.5) * kExposure;
      const Vector3d centre = kCentre + Vector3d(kVelocity.x(), 0, kVelocity.y()) * t;
      const Vector3d v = centre - g.eye;
      const double b = d.dot(v);
      inside += b > 0 && v.squaredNorm() - b * b < kRadius * kRadius;
    }
    const double value = kBack + (kBody - kBack) * inside / kInstants;
    image.at<cv::Vec3b>(static_cast<int>(raw[k].y()), static_cast<int>(raw[k].x())) =
        cv::Vec3b::all(static_cast<uchar>(std::lround(255 * value)));
  }
  return image;
}

struct ShearedClip {
  cv::Mat occluder = cv::Mat::zeros(kHeight, kWidth, CV_8U);
  OutlineGeometry geometry = Geometry(&occluder);
  BackgroundModel background{cv::Mat(kHeight, kWidth, CV_8U, cv::Scalar(255)), Transfer::kLinear};
  double reference_row = geometry.Project(kCentre.x(), kCentre.z()).y();
  cv::Mat frame;

  // background_known false: no picture without the ball was seen, and each ray's background is
  // solved with its colours.
  explicit ShearedClip(double readout, bool background_known = true) : frame(Render(geometry, reference_row, readout)) {
    // The background learnt from pictures without the ball.
    const cv::Mat empty(kHeight, kWidth, CV_8UC3, cv::Scalar::all(std::lround(255 * kBack)));
    for (int i = 0; i < (background_known ? 3 : 0); ++i) {
      background.Measure(empty, cv::Rect());
      background.Learn(empty, cv::Rect());
    }
  }

  // The fit from the true centre and motion (moved by `start_offset`, m), the rows' delay taken
  // as `row_delay`.
  FitOutcome Fit(double row_delay, const Vector2d& start_offset = Vector2d::Zero(), int iterations = 3) const {
    FitRequest q;
    q.iterations = iterations;
    q.centre = Vector2d(kCentre.x(), kCentre.z()) + start_offset;
    q.velocity = kVelocity;
    q.smear = kVelocity * kExposure;
    q.smear_sigma = 0.1 * q.smear.norm();
    q.row_delay = row_delay;
    q.reference_row = reference_row;
    q.estimate_row_delay = true;
    q.half_width_px = 2;
    q.noise = 0.004;  // the 8-bit quantisation, linear units
    return FitOutline(geometry, FrameView{frame, {0, 0}, 1.0}, background, q);
  }

  double CentreErrorPx(const FitOutcome& f) const {
    return (geometry.Project(f.p[kCentreX], f.p[kCentreZ]) - geometry.Project(kCentre.x(), kCentre.z())).norm();
  }
};

// The readout (s) that the fit's rays prefer, fitted at `readout`.
double FittedReadout(const ShearedClip& clip, double readout) {
  const FitOutcome f = clip.Fit(readout / kHeight);
  EXPECT_TRUE(f.ok);
  EXPECT_GT(f.row_delay_sigma, 0);
  std::printf("  fitted at %.2f ms: %.2f ms (± %.2f); centre %.3f px from the truth\n", 1e3 * readout,
              1e3 * f.row_delay * kHeight, 1e3 * f.row_delay_sigma * kHeight, clip.CentreErrorPx(f));
  return f.row_delay * kHeight;
}

// A phone's 25 ms: estimated at the truth, the truth (measured 25.2 ms); at a global shutter (0),
// one Gauss–Newton step away, an estimate near it (measured 26.4 ms: the limb profile's depths,
// held at the unsheared start, add to the step's error; 24.4 ms without it), and at that estimate
// (as the tracker does frame after frame), the truth again (measured 25.0 ms).
TEST(RollingShutter, ReadoutOfAPhoneIsFoundFromAGlobalShutter) {
  constexpr double kReadout = 0.025;
  const ShearedClip clip(kReadout);
  EXPECT_NEAR(FittedReadout(clip, kReadout), kReadout, 0.02 * kReadout);
  const double first = FittedReadout(clip, 0);
  EXPECT_NEAR(first, kReadout, 0.08 * kReadout);
  EXPECT_NEAR(FittedReadout(clip, first), kReadout, 0.02 * kReadout);
}

// Twice as long: from a global shutter the step falls short by the square of its length
// (measured 44.5 ms), the second lands within 2 % (measured 49.9 ms).
TEST(RollingShutter, LongReadoutIsFoundInTwoSteps) {
  constexpr double kReadout = 0.050;
  const ShearedClip clip(kReadout);
  const double first = FittedReadout(clip, 0);
  EXPECT_GT(first, 0.8 * kReadout);
  EXPECT_NEAR(FittedReadout(clip, first), kReadout, 0.02 * kReadout);
}

// A global shutter is measured as one (measured 0.5 ms of a 33 ms frame, ± 0.3).
TEST(RollingShutter, GlobalShutterIsMeasuredAsOne) {
  const ShearedClip clip(0);
  EXPECT_NEAR(FittedReadout(clip, 0), 0, 0.001);
}

// ---- The fit's convergence (outline_fit.hpp) ----------------------------------------------------

// The picture's pixels per metre of the centre's move along the motion, near the centre.
double PxPerMetreAlongTheMotion(const ShearedClip& clip) {
  const Vector2d along = kVelocity.normalized();
  return (clip.geometry.Project(kCentre.x() + 1e-4 * along.x(), kCentre.z() + 1e-4 * along.y()) -
          clip.geometry.Project(kCentre.x(), kCentre.z())).norm() / 1e-4;
}

// The solve converges: started 1.5 px off along the motion (most of the window's half width) it
// ends within 0.04 px of the true centre, as it does started at the truth (measured: 0.014 to
// 0.027 px from the fit started at the truth; the same after 3 iterations as after 20: what is
// left comes from the rays' windows and the limb profile's depths, both placed around the start;
// without the limb profile 0.008 to 0.016 px).
// Truth: the centre the brute-force picture of a global shutter was rendered with. With the rays'
// colours held and their span not removed from the Jacobian (version 9's) the fit ends 0.9 px
// short with the background known and about 1 px with it unknown.
void ExpectConvergence(bool background_known) {
  const ShearedClip clip(0, background_known);
  const FitOutcome from_truth = clip.Fit(0);
  ASSERT_TRUE(from_truth.ok);
  EXPECT_LT(clip.CentreErrorPx(from_truth), 0.02);
  const Vector2d along = kVelocity.normalized();
  const double px_per_m = PxPerMetreAlongTheMotion(clip);
  for (double sign : {-1.0, 1.0}) {
    const FitOutcome from_off = clip.Fit(0, sign * 1.5 / px_per_m * along);
    ASSERT_TRUE(from_off.ok);
    const double apart = (clip.geometry.Project(from_off.p[kCentreX], from_off.p[kCentreZ]) -
                          clip.geometry.Project(from_truth.p[kCentreX], from_truth.p[kCentreZ])).norm();
    std::printf("  started %+.1f px off: ends %.4f px from the truth, %.4f px from the fit started there\n",
                1.5 * sign, clip.CentreErrorPx(from_off), apart);
    EXPECT_LT(clip.CentreErrorPx(from_off), 0.04);
  }
}

TEST(OutlineFit, ConvergesFromAPixelAndAHalfOffWithTheBackgroundKnown) { ExpectConvergence(true); }

TEST(OutlineFit, ConvergesFromAPixelAndAHalfOffWithTheBackgroundSolvedPerRay) { ExpectConvergence(false); }

// The last step the fit reports (FitOutcome::last_step_px, which the tracker reads to decide
// whether a coarse pass had settled): after one iteration it is the whole move from the start,
// measured here from the start and the result; after three from 1.5 px off, a small fraction of
// it (measured: 1.45 px in one iteration, the last of three 0.003 px). Truth: the projections of
// the start and of the result.
TEST(OutlineFit, LastStepIsTheCentresMoveInTheSolvesLastIteration) {
  const ShearedClip clip(0);
  const Vector2d along = kVelocity.normalized();
  const double px_per_m = PxPerMetreAlongTheMotion(clip);
  const Vector2d offset = 1.5 / px_per_m * along;
  const Vector2d start = clip.geometry.Project(kCentre.x() + offset.x(), kCentre.z() + offset.y());
  const FitOutcome one = clip.Fit(0, offset, 1);
  ASSERT_TRUE(one.ok);
  const double moved = (clip.geometry.Project(one.p[kCentreX], one.p[kCentreZ]) - start).norm();
  EXPECT_GT(moved, 1.0);
  EXPECT_NEAR(one.last_step_px, moved, 1e-9);
  const FitOutcome three = clip.Fit(0, offset, 3);
  ASSERT_TRUE(three.ok);
  std::printf("  one iteration: moved %.4f px; three: last step %.4f px\n", moved, three.last_step_px);
  EXPECT_GT(three.last_step_px, 0);
  EXPECT_LT(three.last_step_px, 0.1 * moved);
}

// ---- Settling a clip's row delay (row_delay_settle.hpp) ----------------------------------------

constexpr double kMost = 1.0 / kFps / kHeight;  // s per row: a readout of the whole frame time

// Frames whose estimates are a Gauss–Newton step's, off by k·(q − truth)² from the truth when
// fitted at q (each frame's scatter about it ± spread): two fitted at a global shutter's 0, far
// from the truth, three near it. The first mean is pulled off by the far two (by 2/5 of their
// 0.1·kMost); they are fitted again there, and the second mean is off by 2/5 of k·(first mean −
// truth)² only. Truth: the closed form. A far frame whose refit fails is left out.
TEST(RowDelaySettle, FarFramesAreFittedAgainAtTheMean) {
  const double truth = 0.6 * kMost, spread = 0.05 * kMost;
  const double k = 0.1 * kMost / ((0.6 * kMost) * (0.6 * kMost));
  const double offsets[5] = {-2, -1, 0, 1, 2};  // × spread: mean 0, sample SD sqrt(2.5)
  const std::vector<double> fitted_at = {0, 0, truth, truth, truth};
  const auto estimate = [&](size_t i, double q) {
    return FrameDelay{truth + offsets[i] * spread + k * (q - truth) * (q - truth), 0.01 * kMost};
  };
  for (const bool refit_fails : {false, true}) {
    std::vector<FrameFit> fits;
    for (size_t i = 0; i < 5; ++i) fits.push_back(estimate(i, fitted_at[i]));
    std::vector<size_t> refitted;
    const auto refit = [&](size_t i, double q) -> FrameFit {
      refitted.push_back(i);
      if (refit_fails && i == 1) return std::nullopt;
      return estimate(i, q);
    };
    const std::optional<SettledDelay> settled = SettleRowDelay(fits, fitted_at, 0.2 * kMost, kMost, 4, refit);
    ASSERT_TRUE(settled.has_value());
    EXPECT_EQ(refitted, (std::vector<size_t>{0, 1}));
    const double first = truth + 2 * 0.1 * kMost / 5;
    if (!refit_fails) {
      EXPECT_EQ(settled->frames, 5);
      EXPECT_EQ(settled->refitted, 2);
      const double bias = k * (first - truth) * (first - truth);  // each refitted frame's
      EXPECT_NEAR(settled->delay, truth + 2 * bias / 5, 1e-12 * kMost);
      // The formal errors (0.01/sqrt(5)) are far below the scatter's: the sample SD of the
      // estimates over sqrt(5), the offsets' sqrt(2.5)·spread with the two refits' bias.
      double mean = 0, square = 0;
      for (size_t i = 0; i < 5; ++i) mean += (offsets[i] * spread + (i < 2 ? bias : 0)) / 5;
      for (size_t i = 0; i < 5; ++i) square += std::pow(offsets[i] * spread + (i < 2 ? bias : 0) - mean, 2);
      EXPECT_NEAR(settled->u, std::sqrt(square / 4 / 5), 1e-12 * kMost);
      EXPECT_NEAR(settled->u, std::sqrt(2.5 / 5) * spread, 0.01 * spread);
    } else {
      EXPECT_EQ(settled->frames, 4);
      EXPECT_EQ(settled->refitted, 1);
      // Frames 0, 2, 3, 4: offsets −2, 0, 1, 2 (mean 0.25), frame 0 with its refit's bias.
      const double bias = k * (first - truth) * (first - truth);
      EXPECT_NEAR(settled->delay, truth + 0.25 * spread + bias / 4, 1e-12 * kMost);
    }
  }
}

// The standard error is the formal one where the frames agree within it, the scatter's where they
// do not; too few frames settle nothing.
TEST(RowDelaySettle, StandardErrorIsTheLargerOfFormalAndScatter) {
  const std::vector<FrameFit> tight(4, FrameDelay{1.0, 2.0});
  const std::optional<DelayMean> t = PreferredDelay(tight, 2);
  ASSERT_TRUE(t.has_value());
  EXPECT_DOUBLE_EQ(t->mean, 1.0);
  EXPECT_DOUBLE_EQ(t->se, 1.0);  // 2/sqrt(4)
  // Weights 4:1: mean (4·1 + 1·6)/5 = 2; scatter Σw(e − m)²/((n − 1)Σw) = (4·1 + 1·16)/(1·5) = 4.
  const std::vector<FrameFit> wide = {FrameDelay{1.0, 0.5}, FrameDelay{6.0, 1.0}, std::nullopt};
  const std::optional<DelayMean> w = PreferredDelay(wide, 2);
  ASSERT_TRUE(w.has_value());
  EXPECT_DOUBLE_EQ(w->mean, 2.0);
  EXPECT_DOUBLE_EQ(w->se, 2.0);
  EXPECT_FALSE(PreferredDelay(wide, 3).has_value());
  const auto never = [](size_t, double) -> FrameFit { return std::nullopt; };
  EXPECT_FALSE(SettleRowDelay(std::vector<FrameFit>(6), std::vector<double>(6, 0.0), 0, kMost, 5, never).has_value());
}

// On the brute-force picture of a phone's 25 ms readout, two frames fitted at a global shutter's
// 0 and settled through the fits themselves: the truth within 2 %. One picture stands for two
// frames (the mean needs two), so only the delay is checked.
TEST(RowDelaySettle, PhoneReadoutSettlesOnTheTruth) {
  constexpr double kReadout = 0.025;
  const ShearedClip clip(kReadout);
  const auto fit = [&](double q) -> FrameFit {
    const FitOutcome f = clip.Fit(q);
    return f.ok && f.row_delay_sigma > 0 ? FrameFit(FrameDelay{f.row_delay, f.row_delay_sigma}) : std::nullopt;
  };
  const FrameFit first = fit(0);
  const std::optional<SettledDelay> settled =
      SettleRowDelay({first, first}, {0, 0}, 0.2 * kMost, kMost, 2, [&](size_t, double q) { return fit(q); });
  ASSERT_TRUE(settled.has_value());
  std::printf("  settled %.2f ms (%d refitted)\n", 1e3 * settled->delay * kHeight, settled->refitted);
  EXPECT_EQ(settled->refitted, 2);
  EXPECT_NEAR(settled->delay * kHeight, kReadout, 0.02 * kReadout);
}

}  // namespace
}  // namespace uphill::internal
