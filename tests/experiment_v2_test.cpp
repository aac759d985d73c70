// Experiment folders of format uphill-experiment/2 (data/README.md): the trials' recordings
// (`camera`, `scenes`, `video_analysis` in experiment.json; `video`, `scene` columns), an empty Y
// in a row with a video, version-1 files refusing version-2 features, and paths that must stay in
// the folder. Truth: the files written here (round trips of what was typed) and the format's
// rules as data/README.md states them.
#include <gtest/gtest.h>

#include <fstream>

#include "file_test_support.hpp"
#include "experiment_test_support.hpp"
#include "io/experiment.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

std::string Folder(const std::string& name, const std::string& json, const std::string& csv) {
  const auto dir = FreshFolder("exp2-" + name);
  std::ofstream(dir / "experiment.json") << json;
  std::ofstream(dir / "measurements.csv") << csv;
  return dir.string();
}

std::string Json(const std::string& format, const std::string& extra) {
  return R"({"format": ")" + format +
         R"(", "body": {"type": "sphere", "R": "12.7 mm"}, "apparatus": {"H": "60 mm", "L": "500 mm"},
  "uncertainties": {"D": "0.2 mm", "Y": "0.5 mm"})" + extra + "}";
}

const std::string kVideoKeys =
    R"(, "camera": "calibration/camera.json", "scenes": {"main": "calibration/scene-main.json"},
  "video_analysis": {"fit": "mu", "u_x": "0.3 mm", "g": "9.81 m/s2"})";

TEST(ExperimentV2, ReadsCameraScenesOptionsAndVideoRows) {
  const Experiment e = LoadExperiment(Folder("read", Json("uphill-experiment/2", kVideoKeys),
                                             "trial,D_mm,Y_mm,video,scene\n"
                                             "t1,150,160,videos/t1.mp4,main\n"
                                             "t2,150,,videos/t2.mp4,\n"
                                             "t3,150,161,,\n"));
  // The one error: row 3's Y waits for its video.
  ASSERT_EQ(e.Errors().size(), 1u);
  EXPECT_NE(e.Errors()[0].find("row 3, column Y: is empty and the video 'videos/t2.mp4' has not been analysed"),
            std::string::npos)
      << e.Errors()[0];
  EXPECT_EQ(e.format_version, 2);
  EXPECT_EQ(e.camera, "calibration/camera.json");
  ASSERT_EQ(e.scenes.size(), 1u);
  EXPECT_EQ(e.scenes.at("main"), "calibration/scene-main.json");
  EXPECT_EQ(e.video_analysis.fit, "mu");
  EXPECT_DOUBLE_EQ(e.video_analysis.u_x, 0.3e-3);
  EXPECT_DOUBLE_EQ(e.video_analysis.g, 9.81);
  ASSERT_EQ(e.rows.size(), 3u);
  EXPECT_EQ(e.rows[0].video, "videos/t1.mp4");
  EXPECT_EQ(e.rows[0].scene, "main");
  EXPECT_TRUE(e.rows[0].y_typed);
  EXPECT_DOUBLE_EQ(e.rows[0].Y.value, 0.160);
  // An empty scene cell with exactly one scene: that scene. An empty Y: from the video, later.
  EXPECT_EQ(e.rows[1].scene, "main");
  EXPECT_FALSE(e.rows[1].y_typed);
  EXPECT_FALSE(e.rows[1].HasY());
  ASSERT_TRUE(e.rows[1].configuration.has_value());
  EXPECT_TRUE(e.rows[2].video.empty());
  EXPECT_TRUE(e.rows[2].scene.empty());
  EXPECT_TRUE(e.HasVideos());
  // Not usable until the video fills Y in; the reason names the row and the video.
  EXPECT_EQ(e.UsableRows().size(), 2u);
}

TEST(ExperimentV2, DefaultsOfTheVideoAnalysisAreAnalyseTracks) {
  const Experiment e = LoadExperiment(Folder(
      "defaults", Json("uphill-experiment/2", R"(, "camera": "c.json", "scenes": {"a": "a.json"})"),
      "trial,D_mm,video\nt1,150,v.mp4\n"));
  // analyse-track's defaults (tools/uphill/analyse_track_command.cpp): --fit g --u-x 0.5mm --g 9.80665m/s2
  EXPECT_EQ(e.video_analysis.fit, "g");
  EXPECT_DOUBLE_EQ(e.video_analysis.u_x, 0.5e-3);
  EXPECT_DOUBLE_EQ(e.video_analysis.g, 9.80665);
  ASSERT_EQ(e.Errors().size(), 1u);  // no Y column at all: every Y from its video
  EXPECT_NE(e.Errors()[0].find("row 2, column Y: is empty and the video 'v.mp4' has not been analysed"),
            std::string::npos)
      << e.Errors()[0];
}

TEST(ExperimentV2, VersionOneIsReadUnchangedAndRefusesVersionTwoFeatures) {
  const Experiment v1 = LoadExperiment(Folder("v1", Json("uphill-experiment/1", ""), "trial,D_mm,Y_mm\nt1,150,160\n"));
  EXPECT_EQ(v1.format_version, 1);
  EXPECT_EQ(v1.UsableRows().size(), 1u);
  EXPECT_FALSE(v1.HasVideos());
  for (const std::string key : {R"("camera": "c.json")", R"("scenes": {"a": "a.json"})", R"("video_analysis": {})"}) {
    const std::string error = LoadError(Folder("v1key", Json("uphill-experiment/1", ", " + key), "trial,D_mm,Y_mm\nt1,150,160\n"));
    EXPECT_NE(error.find("experiment.json: "), std::string::npos) << error;
    EXPECT_NE(error.find("needs format uphill-experiment/2"), std::string::npos) << error;
  }
  for (const std::string column : {"video", "scene"}) {
    const std::string error =
        LoadError(Folder("v1col", Json("uphill-experiment/1", ""), "trial,D_mm,Y_mm," + column + "\nt1,150,160,\n"));
    EXPECT_NE(error.find("measurements.csv, row 1, column " + column + ": needs format uphill-experiment/2"),
              std::string::npos)
        << error;
  }
  // A v1 row without Y stays an error of that row (Y is required without a video).
  const Experiment empty_y = LoadExperiment(Folder("v1y", Json("uphill-experiment/1", ""), "trial,D_mm,Y_mm\nt1,150,\nt2,150,160\n"));
  ASSERT_EQ(empty_y.Errors().size(), 1u);
  EXPECT_NE(empty_y.Errors()[0].find("row 2, column Y_mm"), std::string::npos) << empty_y.Errors()[0];
  EXPECT_EQ(empty_y.UsableRows().size(), 1u);
}

TEST(ExperimentV2, PathsMustStayInsideTheFolder) {
  for (const std::string bad : {"../camera.json", "/etc/camera.json", "calibration/../../c.json", "a//b.json"}) {
    const std::string error = LoadError(Folder(
        "camera-path", Json("uphill-experiment/2", R"(, "camera": ")" + bad + R"(", "scenes": {"a": "a.json"})"),
        "trial,D_mm,Y_mm\nt1,150,160\n"));
    EXPECT_NE(error.find("experiment.json: camera: '" + bad + "'"), std::string::npos) << error;
    const std::string scene_error = LoadError(Folder(
        "scene-path", Json("uphill-experiment/2", R"(, "camera": "c.json", "scenes": {"a": ")" + bad + R"("})"),
        "trial,D_mm,Y_mm\nt1,150,160\n"));
    EXPECT_NE(scene_error.find("experiment.json: scenes.a: '" + bad + "'"), std::string::npos) << scene_error;
    // A video cell: that row's error; the other row is still read.
    const Experiment e = LoadExperiment(Folder("video-path", Json("uphill-experiment/2", kVideoKeys),
                                               "trial,D_mm,Y_mm,video\nt1,150,160," + bad + "\nt2,150,161,ok.mp4\n"));
    ASSERT_EQ(e.Errors().size(), 1u) << bad;
    EXPECT_NE(e.Errors()[0].find("measurements.csv, row 2, column video: '" + bad + "'"), std::string::npos)
        << e.Errors()[0];
    EXPECT_EQ(e.UsableRows().size(), 1u);
  }
}

TEST(ExperimentV2, BadVideoRowsAreNamedAndTheOthersKept) {
  const std::string two_scenes = R"(, "camera": "c.json", "scenes": {"left": "l.json", "right": "r.json"})";
  const Experiment e = LoadExperiment(Folder("rows", Json("uphill-experiment/2", two_scenes),
                                             "trial,D_mm,Y_mm,video,scene\n"
                                             "t1,150,160,t1.mp4,\n"         // two scenes: must name one
                                             "t2,150,160,t2.mp4,middle\n"   // not a scene
                                             "t3,150,160,,left\n"           // a scene without a video
                                             "t4,150,,,\n"                  // no Y, no video
                                             "t5,150,160,t5.mp4,right\n"));
  const auto errors = e.Errors();
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_NE(errors[0].find("row 2, column scene: is empty: name one of the 2 scenes"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("row 3, column scene: 'middle' is not a key of experiment.json's scenes"), std::string::npos)
      << errors[1];
  EXPECT_NE(errors[2].find("row 4, column scene: names a scene but the row has no video"), std::string::npos) << errors[2];
  EXPECT_NE(errors[3].find("row 5, column Y_mm"), std::string::npos) << errors[3];
  ASSERT_EQ(e.UsableRows().size(), 1u);
  EXPECT_EQ(e.UsableRows()[0]->scene, "right");

  // A video without a camera or without scenes in experiment.json.
  const Experiment no_camera = LoadExperiment(Folder(
      "nocam", Json("uphill-experiment/2", R"(, "scenes": {"a": "a.json"})"), "trial,D_mm,Y_mm,video\nt1,150,160,v.mp4\n"));
  ASSERT_EQ(no_camera.Errors().size(), 1u);
  EXPECT_NE(no_camera.Errors()[0].find("row 2, column video: a video needs the camera file"), std::string::npos)
      << no_camera.Errors()[0];
}

TEST(ExperimentV2, BadKeysOfExperimentJsonAreNamed) {
  const auto error_of = [](const std::string& name, const std::string& extra) {
    return LoadError(Folder(name, Json("uphill-experiment/2", extra), "trial,D_mm,Y_mm\nt1,150,160\n"));
  };
  EXPECT_NE(error_of("fit", R"(, "video_analysis": {"fit": "x"})").find("video_analysis.fit: must be \"g\""),
            std::string::npos);
  EXPECT_NE(error_of("ux", R"(, "video_analysis": {"u_x": "0 mm"})").find("video_analysis.u_x: must be > 0"),
            std::string::npos);
  EXPECT_NE(error_of("g", R"(, "video_analysis": {"g": "9.8 mm"})").find("video_analysis.g"), std::string::npos);
  EXPECT_NE(error_of("key", R"(, "video_analysis": {"fps": "30"})").find("video_analysis.fps: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of("scenes", R"(, "scenes": {})").find("experiment.json: scenes: must be an object"),
            std::string::npos);
  EXPECT_NE(error_of("camera", R"(, "camera": 3)").find("experiment.json: camera: must be a string"), std::string::npos);
  EXPECT_NE(LoadError(Folder("v3", Json("uphill-experiment/3", ""), "trial,D_mm,Y_mm\nt1,150,160\n"))
                .find("format: must be \"uphill-experiment/1\" or \"uphill-experiment/2\""),
            std::string::npos);
  EXPECT_NE(LoadError(Folder("unit", Json("uphill-experiment/2", kVideoKeys), "trial,D_mm,Y_mm,video_mm\nt1,150,160,\n"))
                .find("column video_mm: 'video' is text"),
            std::string::npos);
}

}  // namespace
}  // namespace uphill::testing
