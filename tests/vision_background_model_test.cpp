// The clip's background model (src/vision/internal/background_model.hpp): what it learns where.
//
// Truth: frames of uniform colour in linear 8-bit codes (Transfer::kLinear: code/255), so that
// the background after n looks is the mean of the codes seen, in closed form, and a pixel never
// seen without the body stays unknown.
#include <gtest/gtest.h>

#include "internal/background_model.hpp"

namespace uphill::internal {
namespace {

constexpr int kWidth = 120, kHeight = 60;

cv::Mat Uniform(int code) { return cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar::all(code)); }

BackgroundModel WholeFrameBand() { return BackgroundModel(cv::Mat(kHeight, kWidth, CV_8U, cv::Scalar(255)), Transfer::kLinear); }

TEST(BackgroundModel, FirstLooksAreAveraged) {
  BackgroundModel model = WholeFrameBand();
  for (int code : {100, 110, 120}) {
    model.Measure(Uniform(code), cv::Rect());
    model.Learn(Uniform(code), cv::Rect());
  }
  // Gain: the first frame has nothing to compare with (1); later frames are measured against
  // the background, which the gain then normalises. So the learnt level is the first frame's
  // code whatever the later ones say (a still scene under changing exposure), 100/255.
  ASSERT_TRUE(model.Known(50, 30));
  EXPECT_NEAR(model.At(50, 30)[1], 100.0 / 255, 1e-6);
}

TEST(BackgroundModel, ExcludedAndOutsideTheLearntRectStayUnknown) {
  BackgroundModel model = WholeFrameBand();
  const cv::Rect body(40, 20, 20, 20), within(30, 10, 50, 40);
  model.Learn(Uniform(80), body, within);
  EXPECT_FALSE(model.Known(50, 30));  // under the body
  EXPECT_FALSE(model.Known(10, 30));  // outside `within`
  EXPECT_FALSE(model.Known(90, 5));
  ASSERT_TRUE(model.Known(32, 12));  // inside `within`, clear of the body
  EXPECT_NEAR(model.At(32, 12)[0], 80.0 / 255, 1e-6);
  // The whole band when `within` is empty.
  model.Learn(Uniform(80), body);
  EXPECT_TRUE(model.Known(10, 30));
  EXPECT_TRUE(model.Known(90, 5));
  EXPECT_FALSE(model.Known(50, 30));
}

TEST(BackgroundModel, MeanOfTheFirstLooksThenClampedSteps) {
  // Without Measure the gain stays 1. The first three looks are averaged (η = 1/n): 110/255. From
  // the fourth on, a step is clamped to max(4·noise, 0.01) before η = 1/4 applies: the noise
  // estimate starts at 0.01, so the fourth look's step of 20/255 = 0.078 is cut to 0.04, which
  // keeps a body the tracker missed from being learnt in one frame.
  BackgroundModel model = WholeFrameBand();
  for (int code : {100, 110, 120}) model.Learn(Uniform(code), cv::Rect());
  ASSERT_TRUE(model.Known(60, 30));
  EXPECT_NEAR(model.At(60, 30)[2], 110.0 / 255, 1e-6);
  model.Learn(Uniform(130), cv::Rect());
  EXPECT_NEAR(model.At(60, 30)[2], 110.0 / 255 + 0.25 * 0.04, 1e-6);
}

}  // namespace
}  // namespace uphill::internal
