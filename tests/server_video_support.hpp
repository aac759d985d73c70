// What the tests of the server's video and calibration API share (server_video_test.cpp,
// server_scene_test.cpp): the points make_video wrote (points.csv) as clicks, and a fixture with
// make_video's clip of its default apparatus as a technician's experiment folder.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "server_test_support.hpp"

namespace uphill::testing {

struct ClipPoint {
  std::string name;
  double u, v, x, y, z;  // px, mm
};

inline std::vector<std::vector<std::string>> ReadCsv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

inline std::vector<ClipPoint> ReadPoints(const fs::path& path) {
  std::vector<ClipPoint> out;
  for (const auto& c : ReadCsv(path))
    out.push_back({c[0], std::stod(c[1]), std::stod(c[2]), std::stod(c[3]), std::stod(c[4]), std::stod(c[5])});
  return out;
}

inline json Clicks(const std::vector<ClipPoint>& points) {
  json clicks = json::array();
  for (const ClipPoint& p : points)
    clicks.push_back({{"name", p.name}, {"u", p.u}, {"v", p.v}, {"x", p.x}, {"y", p.y}, {"z", p.z}});
  return clicks;
}

// One clip of make_video's default apparatus (sphere R = 25.4 mm on 8 mm rods, L = 1000 mm,
// H = 100 mm, D = 150 mm) for the whole suite, and a smaller one of another size.
class VideoApiTest : public ServerFixture {
 protected:
  static void SetUpTestSuite() {
    clip_ = new fs::path(FreshFolder("server-video-clip"));
    other_ = new fs::path(FreshFolder("server-video-other"));
    const std::string make = std::string(UPHILL_MAKE_VIDEO);
    ASSERT_EQ(std::system((make + " " + clip_->string() + " --width 480 --height 270 --frames 12 --boards 0 > /dev/null").c_str()), 0);
    ASSERT_EQ(std::system((make + " " + other_->string() + " --width 320 --height 180 --frames 2 --boards 0 > /dev/null").c_str()), 0);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*clip_);
    fs::remove_all(*other_);
    delete clip_;
    delete other_;
  }

  // The experiment of the clip, with the clip's exact camera as its camera file, written as a
  // technician's folder (the server opens it from the files), and one trial t1.
  void MakeClipExperiment() {
    fs::create_directories(dir_ / "calibration");
    fs::create_directories(dir_ / "videos");
    fs::copy_file(*clip_ / "cam.json", dir_ / "calibration" / "camera.json");
    fs::copy_file(*clip_ / "clip.mp4", dir_ / "videos" / "clip.mp4");
    fs::copy_file(*other_ / "clip.mp4", dir_ / "videos" / "small.mp4");
    const json experiment = {{"format", "uphill-experiment/2"},
                             {"body", {{"type", "sphere"}, {"R", "25.4 mm"}}},
                             {"apparatus", {{"L", "1000 mm"}, {"H", "100 mm"}, {"D", "150 mm"}, {"rod_diameter", "8 mm"}}},
                             {"camera", "calibration/camera.json"}};
    std::ofstream(dir_ / "experiment.json") << experiment.dump(2);
    std::ofstream(dir_ / "measurements.csv") << "trial,series,Y_mm,note\nt1,,300,\n";
    Start();
  }
  std::int64_t Version() { return State()["version"].get<std::int64_t>(); }
  std::int64_t FirstRowId() { return State()["rows"][0]["id"].get<std::int64_t>(); }

  // The server starts once the folder is written (a server stopped before it listens would not
  // notice the stop).
  void SetUp() override {}

  static inline fs::path* clip_ = nullptr;
  static inline fs::path* other_ = nullptr;
};

}  // namespace uphill::testing
