// TrackVideoFile (app/track_video_file.hpp) called through its three front ends on the same clip:
// the program (`uphill track`), the page's HTTP API (POST /api/rows/<id>/track, a video trial of
// the folder it serves: app/video_trials.hpp; and the upload of a video) and the Python module
// (uphill.track). Each must find the ball at the same pixels in the same frames, and refuse a
// double cone and a still picture named .mp4 in the same words.
// Truth: agreement of the fronts to the track CSV's printed precision (4 decimals of a pixel),
// which a front with other checks, other calibration or other tracker settings would not reach;
// the clip's ball is tracked against its rendered truth elsewhere (vision_track_test).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "app/track_video_file.hpp"
#include "file_test_support.hpp"
#include "server_test_support.hpp"
#include "tiny_clip_suite.hpp"
#include "use_case_support.hpp"
#include "vision/track_table.hpp"

namespace uphill::testing {
namespace {

// The shared tiny clip of TinyClipSuite, for a fixture that is a server's.
struct TinyClip : TinyClipSuite {
  using TinyClipSuite::CopyClipInto;
  using TinyClipSuite::SetUpTestSuite;
  using TinyClipSuite::TearDownTestSuite;
};

// make_video's default apparatus, as flags, as experiment.json and as Python.
constexpr const char* kRails = "--L 1000mm --H 100mm --D 150mm";
constexpr const char* kSphere = "--body sphere --R 25.4mm --rod-diameter 8mm";
// The model has the double cone on line rails only.
constexpr const char* kDoubleCone = "--body double-cone --R 25.4mm --h 60mm --rod-diameter 0mm";

class TrackUseCase : public ServerFixture {
 protected:
  static void SetUpTestSuite() { TinyClip::SetUpTestSuite(); }
  static void TearDownTestSuite() { TinyClip::TearDownTestSuite(); }
  // The folder the server serves: the clip as the one trial "a" of a version-2 experiment.
  void SetUp() override {
    fs::create_directories(dir_);
    TinyClip::CopyClipInto(dir_);
    WriteExperiment(json{{"type", "sphere"}, {"R", "25.4 mm"}});
    Start();
  }
  void WriteExperiment(const json& body, const std::string& rod_diameter = "8 mm") {
    const json experiment = {{"format", "uphill-experiment/2"},
                             {"body", body},
                             {"apparatus", {{"L", "1000 mm"}, {"H", "100 mm"}, {"D", "150 mm"}, {"rod_diameter", rod_diameter}}},
                             {"camera", "cam.json"},
                             {"scenes", {{"main", "scene.json"}}}};
    std::ofstream(dir_ / "experiment.json") << experiment.dump(2);
    std::ofstream(dir_ / "measurements.csv") << "trial,Y_mm,video\na,,clip.mp4\n";
  }
  std::string TrackFlags(const char* body) const {
    return "track " + (dir_ / "clip.mp4").string() + " --camera " + (dir_ / "cam.json").string() + " --scene " +
           (dir_ / "scene.json").string() + " " + kRails + " " + body + " --quiet -o " + (dir_ / "out" / "track.csv").string();
  }
  // uphill.track of the clip with `body` (Python), its columns or its InputError's text as JSON.
  std::string PythonTrack(const std::string& body, const std::string& rod_radius = "4 mm") const {
    return "import json, math, uphill\n"
           "scene = uphill.Scene(" + body + ", uphill.Rails.from_apparatus('1000 mm', '100 mm', '150 mm'), '" +
           rod_radius + "')\n"
           "d = '" + dir_.string() + "/'\n"
           "try:\n"
           "    r = uphill.track(d + 'clip.mp4', d + 'cam.json', d + 'scene.json', scene)\n"
           "except uphill.InputError as e:\n"
           "    print(json.dumps(str(e)))\n"
           "else:\n"
           "    clean = lambda a: [None if math.isnan(v) else v for v in a.tolist()]\n"
           "    print(json.dumps({'frame': r['frame'].tolist(), 'found': r['found'].tolist(),\n"
           "                      'u': clean(r['u']), 'v': clean(r['v']), 'x': clean(r['x'])}))\n";
  }
  std::int64_t RowId() { return State()["rows"][0]["id"]; }
};

TEST_F(TrackUseCase, TheClipIsTrackedAlikeThroughEveryFront) {
  const CommandResult cli = RunUphill(TrackFlags(kSphere));
  ASSERT_EQ(cli.status, 0) << cli.err;
  const Track from_cli = ReadTrackFile((dir_ / "out" / "track.csv").string());
  ASSERT_GT(from_cli.found_count(), 0u);

  const json from_python = PythonJson(dir_, PythonTrack("uphill.Body.sphere('25.4 mm')"));
  ASSERT_TRUE(from_python.is_object()) << from_python.dump();
  ASSERT_EQ(from_python["frame"].size(), from_cli.frames.size());
  constexpr double kPrinted = 1e-4;  // px: the CSV's 4 decimals (and x's 4 decimals of a mm)
  for (std::size_t i = 0; i < from_cli.frames.size(); ++i) {
    const TrackFrame& f = from_cli.frames[i];
    EXPECT_EQ(from_python["frame"][i].get<long>(), f.frame);
    ASSERT_EQ(from_python["found"][i].get<bool>(), f.found) << "frame " << f.frame;
    if (!f.found) continue;
    EXPECT_NEAR(from_python["u"][i].get<double>(), f.u, kPrinted) << "frame " << f.frame;
    EXPECT_NEAR(from_python["v"][i].get<double>(), f.v, kPrinted) << "frame " << f.frame;
    EXPECT_NEAR(from_python["x"][i].get<double>(), f.x, 1e-7) << "frame " << f.frame;
  }

  const auto [status, from_http] = Send("POST", "/api/rows/" + std::to_string(RowId()) + "/track", json::object());
  ASSERT_EQ(status, 200) << from_http.dump();
  EXPECT_EQ(from_http["frames"].get<std::size_t>(), from_cli.frames.size());
  EXPECT_EQ(from_http["frames_tracked"].get<std::size_t>(), from_cli.found_count());
  std::map<long, const TrackFrame*> by_frame;
  for (const TrackFrame& f : from_cli.frames) by_frame[f.frame] = &f;
  ASSERT_FALSE(from_http["strip"].empty());
  for (const json& s : from_http["strip"]) {
    const TrackFrame& f = *by_frame.at(s["frame"].get<long>());
    ASSERT_EQ(!s["u"].is_null(), f.found);
    if (!f.found) continue;
    // Both read from a track CSV: the same printed digits.
    EXPECT_NEAR(s["u"].get<double>(), f.u, 1e-9);
    EXPECT_NEAR(s["v"].get<double>(), f.v, 1e-9);
    EXPECT_NEAR(s["x"].get<double>(), f.x * 1e3, 1e-6);  // the experiment's unit: mm
  }
}

// AnalyseExperimentFolder (app/experiment_folder_analysis.hpp) of a folder with a video: the
// program, the page's report and Python's analyse_experiment track it and analyse alike.
TEST_F(TrackUseCase, AFolderWithTheClipIsAnalysedAlikeThroughEveryFront) {
  Stop();
  std::ofstream(dir_ / "measurements.csv") << "trial,Y_mm,video\na,,clip.mp4\nb,390,\nc,394,\n";
  Start();
  // Each front tracks the clip itself: the cache one front fills is removed before the next.
  const auto without_cache = [&] { fs::remove_all(dir_ / ".uphill-cache"); };
  const CommandResult cli = RunUphill("fit " + dir_.string() + " --json --quiet --mc-trials 1000");
  ASSERT_EQ(cli.status, 0) << cli.err;
  const json from_cli = WithoutTimes(json::parse(cli.out));
  without_cache();
  const json from_python = WithoutTimes(PythonJson(dir_, "import json, uphill\n"
                                                         "a = uphill.analyse_experiment('" + dir_.string() +
                                                             "', mc_trials=1000)\n"
                                                         "print(json.dumps(a.to_json()))\n"));
  without_cache();
  const auto [status, answer] = Send("POST", "/api/report", json::object());  // the fixture's 1000 trials
  ASSERT_EQ(status, 200) << answer.dump();
  const json from_http = WithoutTimes(json::parse(ReadBytes(dir_ / "report" / "fit.json")));
  // Trial a's Y is the clip's rest position: all three rows are analysed.
  EXPECT_EQ(from_cli.at("rows").size(), 3u) << cli.out;
  EXPECT_EQ(from_cli, from_http);
  EXPECT_EQ(from_cli, from_python);
}

TEST_F(TrackUseCase, ADoubleConeIsRefusedInTheSameWords) {
  const std::string refusal = std::string("body: ") + kDoubleConeRefusal;
  const CommandResult cli = RunUphill(TrackFlags(kDoubleCone));
  EXPECT_EQ(cli.status, 2);
  EXPECT_EQ(cli.err, "uphill: " + refusal + "\n");
  EXPECT_EQ(PythonJson(dir_, PythonTrack("uphill.Body.double_cone('25.4 mm', '60 mm')", "0 mm")), refusal);
  Stop();
  WriteExperiment(json{{"type", "double-cone"}, {"R", "25.4 mm"}, {"h", "60 mm"}}, "0 mm");
  Start();
  const auto [status, http] = Send("POST", "/api/rows/" + std::to_string(RowId()) + "/track", json::object());
  EXPECT_EQ(status, 422);
  EXPECT_EQ(http.value("error", ""), "video: trial 'a' (clip.mp4): " + refusal) << http.dump();
}

// A PNG named .mp4 opens in FFmpeg as a video of one frame: it is refused as a still picture by
// the program (exit 2), by Python, and at the page's upload (422, nothing kept). Truth: the rule
// of app/video_frames.hpp (a recording has at least kMinVideoFrames frames) and a file that has one.
TEST_F(TrackUseCase, AStillPictureIsRefusedInTheSameWords) {
  const fs::path png = dir_ / "still.png", still = dir_ / "clip.mp4";
  ASSERT_TRUE(cv::imwrite(png.string(), cv::Mat(360, 480, CV_8UC3, cv::Scalar(90, 120, 150))));
  fs::rename(png, still);  // in place of the clip: the same flags and the same Python call
  const std::string rule = ": is a still picture, not a video: it holds 1 frame (a recording has at least 2)";
  const CommandResult cli = RunUphill(TrackFlags(kSphere));
  EXPECT_EQ(cli.status, 2);
  EXPECT_EQ(cli.err, "uphill: " + still.string() + rule + "\n");
  EXPECT_EQ(PythonJson(dir_, PythonTrack("uphill.Body.sphere('25.4 mm')")), still.string() + rule);
  auto upload = client_->Put("/api/videos/still.mp4", ReadBytes(still), "application/octet-stream");
  ASSERT_TRUE(upload);
  EXPECT_EQ(upload->status, 422);
  EXPECT_EQ(json::parse(upload->body).value("error", ""), "still.mp4" + rule) << upload->body;
  EXPECT_FALSE(fs::exists(dir_ / "videos" / "still.mp4"));
}

}  // namespace
}  // namespace uphill::testing
