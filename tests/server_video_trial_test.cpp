// A trial created from its recording when D varies per row (issue 32, item 5), through the page's
// route (POST /api/rows/new/video), with a real clip of tools/make_video: the row is created with
// the video alone, its setting and Y left empty (never a placeholder), flagged until they come.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "file_test_support.hpp"
// Last: it includes <httplib.h>, which includes <resolv.h>, whose `_res` macro breaks Eigen.
#include "server_test_support.hpp"

namespace uphill::testing {
namespace {

class VideoTrialTest : public ServerFixture {
 protected:
  void SetUp() override {}  // started once the folder is written
  void TearDown() override {
    ServerFixture::TearDown();
    fs::remove_all(clip_);
  }
  fs::path clip_ = FreshFolder("server-video-trial-clip");
};

TEST_F(VideoTrialTest, ANewTrialFromItsVideoWaitsForItsSetting) {
  ASSERT_EQ(std::system((std::string(UPHILL_MAKE_VIDEO) + " " + clip_.string() +
                         " --width 320 --height 180 --frames 2 --boards 0 > /dev/null").c_str()),
            0);
  fs::create_directories(dir_ / "calibration");
  fs::create_directories(dir_ / "videos");
  fs::copy_file(clip_ / "cam.json", dir_ / "calibration" / "camera.json");
  fs::copy_file(clip_ / "clip.mp4", dir_ / "videos" / "t2.mp4");
  const json experiment = {{"format", "uphill-experiment/2"},
                           {"body", {{"type", "sphere"}, {"R", "25.4 mm"}}},
                           {"apparatus", {{"L", "1000 mm"}, {"H", "100 mm"}, {"rod_diameter", "8 mm"}}},
                           {"camera", "calibration/camera.json"}};
  std::ofstream(dir_ / "experiment.json") << experiment.dump(2);
  std::ofstream(dir_ / "measurements.csv") << "trial,series,D_mm,Y_mm,note\nt1,,150,300,\n";
  Start();
  auto [status, state] = Send("POST", "/api/rows/new/video",
                              {{"version", State()["version"]}, {"trial", "t2"}, {"video", "videos/t2.mp4"}});
  ASSERT_EQ(status, 200) << state.dump();
  ASSERT_EQ(state["rows"].size(), 2u);
  const json& row = state["rows"][1];
  EXPECT_EQ(row["trial"], "t2");
  EXPECT_EQ(row["video"], "videos/t2.mp4");
  EXPECT_FALSE(row.contains("D"));
  EXPECT_FALSE(row.contains("Y"));
  EXPECT_EQ(FlagCodes(row["check"]), std::vector<std::string>{"invalid"});
  std::ifstream in(dir_ / "measurements.csv");
  std::stringstream csv;
  csv << in.rdbuf();
  EXPECT_EQ(csv.str(), "trial,series,D_mm,Y_mm,video,note\nt1,,150,300,,\nt2,,,,videos/t2.mp4,\n");
  // The technician types D in the row: accepted, Y still to come from the video.
  json edited = row;
  edited.erase("check");
  edited.erase("id");
  edited["D"] = "150";
  std::tie(status, state) = Send("PUT", "/api/rows/" + std::to_string(row["id"].get<std::int64_t>()),
                                 {{"version", State()["version"]}, {"row", edited}});
  ASSERT_EQ(status, 200) << state.dump();
  EXPECT_EQ(state["rows"][1]["D"], "150");
  EXPECT_FALSE(state["rows"][1].contains("Y"));
  EXPECT_EQ(state["fit"]["n"], 1);  // only t1: t2 has no Y yet
}

}  // namespace
}  // namespace uphill::testing
