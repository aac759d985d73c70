// What the program writes, end to end (issue 11): every output file is whole or absent, even on a
// full disk or with something in the way; an output never replaces an input or anything that is
// not a regular file; and the user's environment gets exit status 2 with one line, never 1.
// Truth: the formats' own ends (an SVG's closing tag, a PNG's IEND chunk, JSON that parses, HTML
// that closes), the bytes of the inputs before and after, and the exit-code table of docs/exit-codes.md.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "cli_test_support.hpp"
#include "file_test_support.hpp"
#include "tiny_clip_suite.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::RunUphill;

const std::string kSource = UPHILL_SOURCE_DIR;
const std::string kProgram = UPHILL_PROGRAM;

const auto Slurp = testing::ReadBytes;

// A path for an output folder that does not exist yet.
fs::path Fresh(const std::string& name) {
  const fs::path dir = testing::FreshFolder(name);
  fs::remove(dir);
  return dir;
}

// Whether a file the report writes is complete, judged by its format's own end.
bool Complete(const fs::path& path) {
  const std::string s = Slurp(path);
  const std::string ext = path.extension().string();
  const auto ends_with = [&](const std::string& tail) {
    const auto end = s.find_last_not_of(" \t\r\n");
    return end != std::string::npos && end + 1 >= tail.size() && s.compare(end + 1 - tail.size(), tail.size(), tail) == 0;
  };
  if (ext == ".svg") return ends_with("</svg>");
  if (ext == ".png") return s.size() > 20 && s.compare(s.size() - 12, 12, std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12)) == 0;
  if (ext == ".json") return json::accept(s);
  if (ext == ".html") return ends_with("</html>");
  if (ext == ".md" || ext == ".dat" || ext == ".gp") return !s.empty() && s.back() == '\n';
  return false;
}

// `uphill report` with the size of any file it may write limited (RLIMIT_FSIZE through the
// shell's `ulimit -f`, in its blocks), as a full disk would: writes beyond it fail with EFBIG,
// gnuplot's too (SIGXFSZ ignored, as a full disk sends no signal).
int ReportWithFileSizeLimit(const fs::path& out, int blocks) {
  const std::string command = "sh -c 'ulimit -f " + std::to_string(blocks) + "; trap \"\" XFSZ; exec " + kProgram +
                              " report " + kSource + "/data/series1-fixed-D -o " + out.string() +
                              " --mc-trials 1000' > /dev/null 2> " + out.string() + ".err";
  const int raw = std::system(command.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

TEST(OutputCli, AFullDiskLeavesEveryReportFileWholeOrAbsent) {
  // Limits from "not even one image fits" to "all but report.html fit" (the report's files are
  // 1 KiB to ~150 KiB; the sizes of the shell's blocks do not matter, only that the run fails).
  for (int kib : {8, 30, 80, 120}) {
    const fs::path out = Fresh("full-" + std::to_string(kib));
    const int status = ReportWithFileSizeLimit(out, kib);
    const std::string err = Slurp(out.string() + ".err");
    EXPECT_EQ(status, 2) << kib << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    for (const auto& entry : fs::directory_iterator(out)) {
      const std::string name = entry.path().filename().string();
      EXPECT_NE(name[0], '.') << kib << " KiB: a temporary was left behind: " << name;
      EXPECT_TRUE(Complete(entry.path())) << kib << " KiB: " << name << " is half-written";
    }
    fs::remove_all(out);
    fs::remove(out.string() + ".err");
  }
}

TEST(OutputCli, AFolderInTheWayOfAFigureIsNamedAndLeavesNoTemporaries) {
  const fs::path out = Fresh("in-the-way");
  fs::create_directories(out / "fit_offset.svg");
  const auto r = RunUphill("report " + kSource + "/data/series1-fixed-D -o " + out.string() + " --mc-trials 1000");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("fit_offset.svg"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("folder"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_directory(out / "fit_offset.svg"));
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    EXPECT_NE(name[0], '.') << "a temporary was left behind: " << name;
    if (name != "fit_offset.svg") {
      EXPECT_TRUE(Complete(entry.path())) << name;
    }
  }
  fs::remove_all(out);
}

// Issue 11: `uphill track` overwrote its input video when -o or --overlay named it (a relative
// path, "./", a symbolic link), and as root replaced the device /dev/full with a regular file;
// --overlay into a missing folder failed (exit 1) where -o creates its folder. Truth: the input's
// bytes before and after, lstat of /dev/full, and docs/exit-codes.md (status 2, one line naming
// the flag). The clip: tools/make_video (12 frames).
class TrackOutputCli : public testing::TinyClipSuite {
 protected:
  // `uphill track` on the clip in `work` (make_video's apparatus), `outputs` appended.
  static testing::CommandResult Track(const fs::path& work, const std::string& outputs) {
    return RunUphill("track " + (work / "clip.mp4").string() + " --camera " + (work / "cam.json").string() +
                     " --scene " + (work / "scene.json").string() +
                     " --body sphere --R 25.4mm --L 1000mm --H 100mm --D 150mm --rod-diameter 8mm --quiet " + outputs);
  }
  static fs::path Work(const std::string& name) {
    const fs::path work = testing::FreshFolder(name);
    CopyClipInto(work);
    return work;
  }
};

TEST_F(TrackOutputCli, NeverWritesOverItsInputsOrADevice) {
  const fs::path work = Work("track-inputs");
  fs::create_symlink(work / "clip.mp4", work / "link.mp4");
  const std::string video = Slurp(work / "clip.mp4");
  const std::string w = work.string();
  for (const std::string& outputs : std::vector<std::string>{
           "-o " + w + "/clip.mp4", "-o " + w + "/t.csv --overlay " + w + "/./clip.mp4",
           "-o " + w + "/t.csv --overlay " + w + "/link.mp4", "-o " + w + "/cam.json", "-o /dev/full",
           "-o " + w + "/t.csv --overlay /dev/full"}) {
    const auto r = Track(work, outputs);
    EXPECT_EQ(r.status, 2) << outputs << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    const std::string flag = outputs.find("--overlay") != std::string::npos ? "--overlay" : "-o";
    EXPECT_EQ(r.err.rfind("uphill: " + flag + " ", 0), 0u) << r.err;
    EXPECT_EQ(Slurp(work / "clip.mp4"), video) << outputs << ": the input video was changed";
  }
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status("/dev/full")));
  EXPECT_FALSE(fs::exists(work / "t.csv"));  // refused before any work
  fs::remove_all(work);
}

TEST_F(TrackOutputCli, OverlayAndTrackGoIntoFoldersThatDoNotExistYet) {
  const fs::path work = Work("track-new-folders");
  const auto r = Track(work, "-o " + (work / "out/t.csv").string() + " --overlay " + (work / "shots/o.mp4").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_GT(fs::file_size(work / "out/t.csv"), 0u);
  EXPECT_GT(fs::file_size(work / "shots/o.mp4"), 0u);
  fs::remove_all(work);
}

// `uphill track`'s exit status on partial tracks (docs/track.md, "Output"): a video cut mid-file
// (FFV1 in .avi, cut at 60 % of its bytes) keeps the frames read and exits 2; a ball that drops
// between the rails near the end is how runs end: partial, exit 0. Truth: the sidecar's own
// count of rows against the CSV, and docs/exit-codes.md. Clips: tools/make_video.
TEST(TrackExitCli, ACutVideoExitsTwoAndABallLostAtTheEndZero) {
  const fs::path work = testing::FreshFolder("track-exit");
  const auto make = [&](const std::string& flags) {
    const std::string command = std::string(UPHILL_MAKE_VIDEO) + " " + work.string() +
                                " --width 480 --height 270 --boards 0 " + flags + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  };
  const auto track = [&](const std::string& video, const std::string& csv) {
    return RunUphill("track " + (work / video).string() + " --camera " + (work / "cam.json").string() + " --scene " +
                     (work / "scene.json").string() +
                     " --body sphere --R 25.4mm --L 1000mm --H 100mm --D 150mm --rod-diameter 8mm --quiet -o " +
                     (work / csv).string());
  };
  const auto rows = [&](const std::string& csv) {
    const std::string text = Slurp(work / csv);
    return static_cast<int>(std::count(text.begin(), text.end(), '\n')) - 1;  // without the header
  };
  make("--frames 24 --lossless --name cut");
  fs::resize_file(work / "cut.avi", fs::file_size(work / "cut.avi") * 6 / 10);
  auto r = track("cut.avi", "cut.csv");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("partial track"), std::string::npos) << r.err;
  const json cut = json::parse(Slurp(work / "cut.csv.json"));
  EXPECT_EQ(cut.at("partial"), true);
  EXPECT_EQ(rows("cut.csv"), cut.at("frames").get<int>());
  EXPECT_GT(rows("cut.csv"), 0);
  EXPECT_LT(rows("cut.csv"), 24);

  make("--mu 0.05 --x0-band 0.3 --release-time 0.2 --until-end --name falls");
  r = track("falls.mp4", "falls.csv");
  EXPECT_EQ(r.status, 0) << r.err;
  const json falls = json::parse(Slurp(work / "falls.csv.json"));
  EXPECT_EQ(falls.at("partial"), true) << falls.dump();
  EXPECT_EQ(rows("falls.csv"), falls.at("frames").get<int>());
  fs::remove_all(work);
}

}  // namespace
}  // namespace uphill
