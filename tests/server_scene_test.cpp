// The scene by clicks in `uphill serve` (issue 32): the saved scene keeps the clicks, the marks and
// the table's height and gives them back; the leave-one-out check names a moved click; a video
// is detached from its trial and leaves the folder's list.
// Truth: tools/make_video's exact pixels of the apparatus points (points.csv), so the one click
// moved here is the only wrong one; what was sent is what must come back (a round trip); the
// folder's files as they are on disk.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "file_test_support.hpp"
#include "server_test_support.hpp"
#include "server_video_support.hpp"

namespace uphill::testing {
namespace {

class SceneApiTest : public VideoApiTest {
 protected:
  std::pair<int, json> Get(const std::string& path) {
    httplib::Result r = client_->Get(path.c_str());
    if (!r) return {0, json()};
    return {r->status, json::parse(r->body, nullptr, false)};
  }
};

json Names(const json& list) {
  json names = json::array();
  for (const json& p : list) names.push_back(p["name"]);
  return names;
}

// Saved, the scene file keeps the clicks with their names, the marks and the table's height;
// GET /api/scenes/main gives them back as sent (lengths in the experiment's unit), also after a
// restart, and a scene file that keeps none (make_video's) gives empty lists.
TEST_F(SceneApiTest, TheSavedSceneKeepsTheClicksMarksAndTable) {
  MakeClipExperiment();
  const std::vector<ClipPoint> points = ReadPoints(*clip_ / "points.csv");
  const json marks = {300, 600, 900};
  json body = {{"version", Version()}, {"video", "videos/clip.mp4"}, {"row", FirstRowId()},
               {"clicks", Clicks(points)},  {"marks", marks},            {"table_z", -30}};
  auto [status, state] = Send("PUT", "/api/scenes/main", body);
  ASSERT_EQ(status, 200) << state.dump();
  const json file = json::parse(ReadBytes(dir_ / "calibration" / "scene-main.json"));
  ASSERT_EQ(file["points"].size(), points.size());
  EXPECT_EQ(file["points"][0]["name"], points[0].name);
  EXPECT_EQ(file["points"][0]["u_px"].get<double>(), points[0].u);
  EXPECT_NEAR(file["table_z_m"].get<double>(), -0.030, 1e-15);

  for (int restart = 0; restart < 2; ++restart) {
    auto [got, saved] = Get("/api/scenes/main");
    ASSERT_EQ(got, 200) << saved.dump();
    ASSERT_EQ(saved["points"].size(), points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const json& p = saved["points"][i];
      EXPECT_EQ(p["name"], points[i].name);
      EXPECT_EQ(p["u"].get<double>(), points[i].u);  // pixels are stored as sent
      EXPECT_EQ(p["v"].get<double>(), points[i].v);
      EXPECT_NEAR(p["x"].get<double>(), points[i].x, 1e-9);  // mm → m → mm
      EXPECT_NEAR(p["y"].get<double>(), points[i].y, 1e-9);
      EXPECT_NEAR(p["z"].get<double>(), points[i].z, 1e-9);
    }
    ASSERT_EQ(saved["marks"].size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(saved["marks"][i].get<double>(), marks[i].get<double>(), 1e-9);
    EXPECT_NEAR(saved["table_z"].get<double>(), -30, 1e-9);
    Stop();
    Start();
  }

  // A scene file written without its inputs (make_video's) is read as before, with none.
  std::filesystem::copy_file(*clip_ / "scene.json", dir_ / "calibration" / "scene-old.json");
  Stop();
  json experiment = json::parse(ReadBytes(dir_ / "experiment.json"));
  experiment["scenes"]["old"] = "calibration/scene-old.json";
  std::ofstream(dir_ / "experiment.json") << experiment.dump(2);
  Start();
  auto [old_status, old_scene] = Get("/api/scenes/old");
  ASSERT_EQ(old_status, 200) << old_scene.dump();
  EXPECT_EQ(old_scene["points"], json::array());
  EXPECT_EQ(old_scene["marks"], json::array());
  EXPECT_TRUE(old_scene["table_z"].is_null());
  auto [none, none_body] = Get("/api/scenes/absent");
  EXPECT_EQ(none, 422);
  EXPECT_EQ(none_body["field"], "name");
}

// A click moved by 5 px, whichever it is, is the one the leave-one-out check names (the page
// showed the largest residual, O's, when two marks were off); the answer also places the
// unclicked points and the axes (+y toward the left rail) in the frame.
TEST_F(SceneApiTest, TheLeaveOneOutCheckNamesTheMovedClick) {
  MakeClipExperiment();
  const std::vector<ClipPoint> points = ReadPoints(*clip_ / "points.csv");
  ASSERT_GE(points.size(), 6u);
  for (std::size_t wrong = 0; wrong < points.size(); ++wrong) {
    std::vector<ClipPoint> clicks = points;
    clicks[wrong].u += 3;
    clicks[wrong].v -= 4;
    auto [status, answer] = Send("POST", "/api/scene/solve",
                                 {{"video", "videos/clip.mp4"}, {"row", FirstRowId()}, {"clicks", Clicks(clicks)}});
    ASSERT_EQ(status, 200) << answer.dump();
    EXPECT_EQ(answer["leave_one_out"]["name"], points[wrong].name);
    EXPECT_TRUE(answer["leave_one_out"]["explains"].get<bool>()) << answer.dump();
    EXPECT_GT(answer["leave_one_out"]["residual_px"].get<double>(), 4.0);
    EXPECT_LT(answer["leave_one_out"]["rms_without_px"].get<double>(), 0.01);  // the others are exact
    EXPECT_EQ(answer["verdict"], "poor");
    EXPECT_NE(answer["reasons"].dump().find(points[wrong].name + ": "), std::string::npos) << answer["reasons"].dump();
  }
  // Five clicks; the others asked for by name appear where the pose puts them (their true pixels).
  const std::vector<ClipPoint> five(points.begin(), points.begin() + 5);
  json unclicked = json::array();
  for (std::size_t i = 5; i < points.size(); ++i)
    unclicked.push_back({{"name", points[i].name}, {"x", points[i].x}, {"y", points[i].y}, {"z", points[i].z}});
  auto [status, answer] = Send("POST", "/api/scene/solve",
                               {{"video", "videos/clip.mp4"}, {"clicks", Clicks(five)}, {"unclicked", unclicked}});
  ASSERT_EQ(status, 200) << answer.dump();
  ASSERT_EQ(answer["expected"].size(), points.size() - 5) << answer.dump();
  for (std::size_t i = 5; i < points.size(); ++i) {
    const json& e = answer["expected"][i - 5];
    EXPECT_EQ(e["name"], points[i].name);
    EXPECT_NEAR(e["u"].get<double>(), points[i].u, 1e-3);
    EXPECT_NEAR(e["v"].get<double>(), points[i].v, 1e-3);
  }
  EXPECT_EQ(Names(answer["axes"]), json({"O", "+x", "+y (left rail)"}));
}

// Detaching empties the row's video cell (journaled) and moves the file into .detached/, out of
// the folder's list of videos; a file another trial still names stays; a stale version is 409.
TEST_F(SceneApiTest, ADetachedVideoLeavesTheTrialAndTheList) {
  MakeClipExperiment();
  const std::string id = std::to_string(FirstRowId());
  auto [attached, state] = Send("POST", "/api/rows/" + id + "/video", {{"version", Version()}, {"video", "videos/clip.mp4"}});
  ASSERT_EQ(attached, 200) << state.dump();
  auto [added, with_two] = Send("POST", "/api/rows/new/video",
                                {{"version", Version()}, {"video", "videos/clip.mp4"}, {"trial", "t2"}});
  ASSERT_EQ(added, 200) << with_two.dump();
  auto [stale, conflict] = Send("POST", "/api/rows/" + id + "/detach", {{"version", Version() - 1}});
  EXPECT_EQ(stale, 409);

  // Trial t2 still films videos/clip.mp4: the file stays.
  auto [first, kept] = Send("POST", "/api/rows/" + id + "/detach", {{"version", Version()}});
  ASSERT_EQ(first, 200) << kept.dump();
  EXPECT_EQ(kept["moved_to"], "");
  EXPECT_FALSE(kept["state"]["rows"][0].contains("video"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "videos" / "clip.mp4"));

  // Trial t2 has no Y: without its video it would be an empty row, so it keeps it.
  const json t2 = State()["rows"][1];
  const std::string id2 = std::to_string(t2["id"].get<std::int64_t>());
  auto [empty, empty_body] = Send("POST", "/api/rows/" + id2 + "/detach", {{"version", Version()}});
  EXPECT_EQ(empty, 422);
  EXPECT_NE(empty_body["error"].get<std::string>().find("trial t2 has no Y"), std::string::npos) << empty_body.dump();
  json typed = {{"trial", "t2"}, {"Y", "301"}, {"video", "videos/clip.mp4"}};
  auto [edited, edited_body] = Send("PUT", "/api/rows/" + id2, {{"version", Version()}, {"row", typed}});
  ASSERT_EQ(edited, 200) << edited_body.dump();
  auto [second, moved] = Send("POST", "/api/rows/" + id2 + "/detach", {{"version", Version()}});
  ASSERT_EQ(second, 200) << moved.dump();
  EXPECT_EQ(moved["video"], "videos/clip.mp4");
  EXPECT_EQ(moved["moved_to"], ".detached/clip.mp4");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "videos" / "clip.mp4"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / ".detached" / "clip.mp4"));
  EXPECT_EQ(ReadBytes(dir_ / "measurements.csv").find("clip.mp4"), std::string::npos) << ReadBytes(dir_ / "measurements.csv");
  auto [listed, videos] = Get("/api/videos");
  ASSERT_EQ(listed, 200);
  EXPECT_EQ(videos["videos"].dump().find("clip.mp4"), std::string::npos) << videos.dump();

  auto [again, again_body] = Send("POST", "/api/rows/" + id2 + "/detach", {{"version", Version()}});
  EXPECT_EQ(again, 422);
  EXPECT_NE(again_body["error"].get<std::string>().find("has no video"), std::string::npos) << again_body.dump();
}

}  // namespace
}  // namespace uphill::testing
