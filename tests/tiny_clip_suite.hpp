// A test suite sharing one tiny clip, made once per suite by tools/make_video: 480 × 270 px,
// 12 frames of a ball at rest where it was placed (a Y trial's recording: released only after the
// clip), with the camera and scene files of make_video's default apparatus (a sphere of
// R = 25.4 mm on rods of 8 mm diameter, L = 1000 mm, H = 100 mm, D = 150 mm). The test target
// defines UPHILL_MAKE_VIDEO, the make_video program's path.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "file_test_support.hpp"

namespace uphill::testing {

class TinyClipSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    clip_ = new std::filesystem::path(FreshFolder("tiny-clip"));
    const std::string command = std::string(UPHILL_MAKE_VIDEO) + " " + clip_->string() +
                                " --width 480 --height 270 --frames 12 --release-time 10 --boards 0 > /dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*clip_);
    delete clip_;
    clip_ = nullptr;
  }
  // Copies clip.mp4, cam.json and scene.json into the folder `work` (each run gets its own copy:
  // the commands under test may damage their inputs if they are wrong).
  static void CopyClipInto(const std::filesystem::path& work) {
    for (const char* f : {"clip.mp4", "cam.json", "scene.json"}) std::filesystem::copy_file(*clip_ / f, work / f);
  }

 private:
  static inline std::filesystem::path* clip_ = nullptr;
};

}  // namespace uphill::testing
