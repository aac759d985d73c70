// The search's memory of rejected windows (src/vision/internal/rejected_windows.hpp): a window
// counts as unchanged under sensor noise, and as changed as soon as a body enters it, however
// little of it, or the light changes. Truth: the pictures are made here with OpenCV's drawing and
// random functions (a textured table, Gaussian noise of the stated sigma, a disc drawn by
// cv::circle), so what changed between two of them is known by construction.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "internal/rejected_windows.hpp"

namespace uphill::internal {
namespace {

// A 1280 × 720 textured table: smooth random texture around a wood-like colour.
cv::Mat Table() {
  cv::Mat texture(720, 1280, CV_8UC3);
  cv::theRNG().state = 11;
  cv::randu(texture, cv::Scalar(90, 120, 150), cv::Scalar(130, 160, 190));
  cv::GaussianBlur(texture, texture, cv::Size(9, 9), 3);
  return texture;
}

// The picture with independent Gaussian noise of `sigma` levels per channel.
cv::Mat Noisy(const cv::Mat& picture, double sigma, std::uint64_t seed) {
  cv::Mat noise(picture.size(), CV_16SC3), out;
  cv::theRNG().state = seed;
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(sigma));
  picture.convertTo(out, CV_16SC3);
  out += noise;
  out.convertTo(out, CV_8UC3);  // saturating
  return out;
}

const cv::Rect kWindow(500, 300, 180, 200);

TEST(RejectedWindows, NoiseAloneLeavesTheWindowUnchanged) {
  const cv::Mat table = Table();
  for (const double sigma : {1.0, 2.0, 3.0}) {
    RejectedWindows windows;
    windows.Remember(Noisy(table, sigma, 1), kWindow);
    for (std::uint64_t seed = 2; seed < 12; ++seed)
      EXPECT_TRUE(windows.Unchanged(Noisy(table, sigma, seed), kWindow)) << "sigma " << sigma << ", frame " << seed;
    // A box inside the window is judged by the window.
    EXPECT_TRUE(windows.Unchanged(Noisy(table, sigma, 99), cv::Rect(520, 320, 100, 100)));
  }
}

TEST(RejectedWindows, ABodyEnteringTheWindowChangesIt) {
  const cv::Mat table = Table();
  RejectedWindows windows;
  windows.Remember(Noisy(table, 2, 1), kWindow);
  // A yellow disc of radius 37 px (a 2-inch ball at 1080p) whose centre lies outside the window,
  // so that only its edge enters: reaching 15 px in, it covers 1.7 % of the window (625 px), over
  // the 1 % rule. (A candidate's window is its body's box widened by two radii, so a body near
  // the candidate covers about 11 % of it; a thinner sliver is a body centred elsewhere, whose
  // own candidate is fitted.)
  for (const int inside : {15, 30, 74}) {
    cv::Mat frame = table.clone();
    cv::circle(frame, cv::Point(kWindow.x - 37 + inside, kWindow.y + 100), 37, cv::Scalar(40, 200, 220), cv::FILLED,
               cv::LINE_AA);
    EXPECT_FALSE(windows.Unchanged(Noisy(frame, 2, 5), kWindow)) << inside << " px of the disc inside";
  }
  // Of a colour close to the table's (the isoluminant case): a difference of about 15 levels in
  // each channel.
  cv::Mat frame = table.clone();
  cv::circle(frame, cv::Point(kWindow.x + 90, kWindow.y + 100), 37, cv::Scalar(95, 155, 185), cv::FILLED);
  EXPECT_FALSE(windows.Unchanged(Noisy(frame, 2, 5), kWindow));
}

TEST(RejectedWindows, AChangeOfLightChangesIt) {
  const cv::Mat table = Table();
  RejectedWindows windows;
  windows.Remember(Noisy(table, 1, 1), kWindow);
  cv::Mat brighter;
  table.convertTo(brighter, CV_8UC3, 1.06);  // lamp flicker or auto-exposure: +6 %
  EXPECT_FALSE(windows.Unchanged(Noisy(brighter, 1, 2), kWindow));
}

TEST(RejectedWindows, OnlyRememberedWindowsCount) {
  const cv::Mat table = Table();
  RejectedWindows windows;
  EXPECT_FALSE(windows.Unchanged(table, kWindow));
  windows.Remember(table, kWindow);
  EXPECT_FALSE(windows.Unchanged(table, cv::Rect(kWindow.x + 100, kWindow.y, kWindow.width, kWindow.height)));
  // The oldest windows are forgotten beyond kMaxWindows.
  for (int k = 1; k <= RejectedWindows::kMaxWindows; ++k) windows.Remember(table, cv::Rect(10 * k, 10, 50, 50));
  EXPECT_FALSE(windows.Unchanged(table, kWindow));
  EXPECT_TRUE(windows.Unchanged(table, cv::Rect(80, 10, 50, 50)));
  windows.Clear();
  EXPECT_FALSE(windows.Unchanged(table, cv::Rect(80, 10, 50, 50)));
}

}  // namespace
}  // namespace uphill::internal
