// `uphill report` / `uphill fit` of an experiment folder whose trials are videos (docs/fit.md,
// "Trials on video"): `uphill` hands the folder to `uphill-vision`, which tracks the videos; a
// file that is not a video is that trial's error (exit 2) and the rest is reported. Truth: a clip
// of tools/make_video at rest at a known position (its truth CSV), and the files written.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cli_test_support.hpp"
#include "file_test_support.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

TEST(VideoReportCli, ReportsTheVideoTrialsAndNamesTheBadOne) {
  const fs::path dir = FreshFolder("cli-video-report");
  const fs::path clips = dir / "clips";
  const std::string make = std::string(UPHILL_MAKE_VIDEO) + " " + clips.string() +
                           " --width 640 --height 360 --boards 0 --mu 0.05 --x0-band -0.02 --seconds 1 --name rest"
                           " > /dev/null 2>&1";
  ASSERT_EQ(std::system(make.c_str()), 0);
  const fs::path exp = dir / "exp";
  fs::create_directories(exp / "videos");
  fs::copy_file(clips / "cam.json", exp / "camera.json");
  fs::copy_file(clips / "scene.json", exp / "scene.json");
  fs::copy_file(clips / "rest.mp4", exp / "videos" / "rest.mp4");
  std::ofstream(exp / "videos" / "notes.mp4") << "not a video\n";
  std::ofstream(exp / "experiment.json") << R"({"format": "uphill-experiment/2",
    "body": {"type": "sphere", "R": "25.4 mm"}, "apparatus": {"L": "1000 mm", "H": "100 mm", "rod_diameter": "8 mm"},
    "uncertainties": {"D": "0.2 mm", "Y": "0.5 mm"}, "camera": "camera.json", "scenes": {"main": "scene.json"}})";
  std::ofstream(exp / "measurements.csv") << "trial,D_mm,Y_mm,video\n"
                                             "a,150,,videos/rest.mp4\n"
                                             "b,150,,videos/notes.mp4\n"
                                             "c,140,381,\n"
                                             "d,160,325,\n";
  const CommandResult r = RunUphill("report " + exp.string() + " -o " + (dir / "out").string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("trial 'b' (videos/notes.mp4)"), std::string::npos) << r.err;
  // The video's error is printed once (with the videos), not again for the row it leaves without Y.
  const auto count = [](const std::string& text, const std::string& part) {
    std::size_t n = 0;
    for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(r.err, "notes.mp4: is not a video"), 1u) << r.err;
  EXPECT_NE(r.err.find("trial 'b' (videos/notes.mp4): Y is empty and its video could not be analysed"),
            std::string::npos) << r.err;
  const std::string md = ReadBytes(dir / "out" / "report.md");
  EXPECT_NE(md.find("Rest positions from the videos"), std::string::npos);
  EXPECT_NE(md.find("| a | videos/rest.mp4 | \\- |"), std::string::npos) << md;
  EXPECT_EQ(count(md, "notes.mp4: is not a video"), 1u) << md;
  EXPECT_TRUE(fs::exists(dir / "out" / "video_01_x_vs_t.svg"));
  EXPECT_TRUE(fs::exists(exp / ".uphill-cache" / "video"));

  // `uphill fit` of the same folder: the cached results, the same tables as text.
  const CommandResult fit = RunUphill("fit " + exp.string() + " --mc-trials 1000");
  EXPECT_EQ(fit.status, 2);
  EXPECT_NE(fit.out.find("Motion fits"), std::string::npos) << fit.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
