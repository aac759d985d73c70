// The video and calibration API of `uphill serve` (issue 13): a frame of a trial's video, the
// scene calibrated by clicks, the camera from chessboard views, uploads and attaching a video.
// Truth: tools/make_video's exact camera and pose (cam.json, scene.json) and the exact pixels of
// the apparatus points and of the body's centre it rendered (points.csv, truth.csv); frames
// decoded by OpenCV directly; files compared byte for byte.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/socket.h>

#include <algorithm>
#include <csignal>
#include <future>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "file_test_support.hpp"
#include "oversized_media_support.hpp"
#include "vision/camera.hpp"
#include "vision/decode_limits.hpp"
#include "server_test_support.hpp"
#include "server_video_support.hpp"

namespace uphill::testing {
namespace {

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The distance from a point to a polyline (pixels).
double DistanceToPath(double u, double v, const json& path) {
  double best = 1e300;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const double ax = path[i - 1][0], ay = path[i - 1][1], bx = path[i][0], by = path[i][1];
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    const double t = len2 > 0 ? std::clamp(((u - ax) * dx + (v - ay) * dy) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(u - ax - t * dx, v - ay - t * dy));
  }
  return best;
}

// The points offered for the trial are those of calibration/README.md, at the closed-form
// positions make_video wrote (points.csv; marks asked for at 300, 600, 900 mm).
TEST_F(VideoApiTest, OffersTheApparatusPointsOfTheSetting) {
  MakeClipExperiment();
  auto r = client_->Get(("/api/scene/points?row=" + std::to_string(FirstRowId()) + "&table_z=-30&marks=300,600,900").c_str());
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json points = json::parse(r->body)["points"];
  std::map<std::string, json> by_name;
  for (const json& p : points) by_name[p["name"]] = p;
  const std::vector<ClipPoint> truth = ReadPoints(*clip_ / "points.csv");
  ASSERT_GE(truth.size(), 9u);
  for (const ClipPoint& t : truth) {
    ASSERT_TRUE(by_name.count(t.name)) << t.name;
    EXPECT_NEAR(by_name[t.name]["x"].get<double>(), t.x, 1e-6) << t.name;
    EXPECT_NEAR(by_name[t.name]["y"].get<double>(), t.y, 1e-6) << t.name;
    EXPECT_NEAR(by_name[t.name]["z"].get<double>(), t.z, 1e-6) << t.name;
  }
}

// Clicks at the exact pixels give back the pose that rendered the clip (scene.json), the
// residuals vanish, and the model's path of the centre passes through the rendered centre of
// every frame (truth.csv).
TEST_F(VideoApiTest, ClicksAtTheTruePixelsGiveTheTruePose) {
  MakeClipExperiment();
  const json body = {{"video", "videos/clip.mp4"}, {"row", FirstRowId()}, {"clicks", Clicks(ReadPoints(*clip_ / "points.csv"))}};
  auto [status, answer] = Send("POST", "/api/scene/solve", body);
  ASSERT_EQ(status, 200) << answer.dump();
  EXPECT_EQ(answer["verdict"], "good");
  EXPECT_LT(answer["rms_px"].get<double>(), 1e-3);  // points.csv keeps 6 decimals of a pixel
  for (const json& p : answer["points"]) {
    EXPECT_LT(p["residual_px"].get<double>(), 2e-3) << p["name"];
    EXPECT_NEAR(p["u_model"].get<double>(), p["u"].get<double>(), 2e-3);
  }
  const SceneCalibration truth = ReadSceneFile((*clip_ / "scene.json").string());
  const Eigen::Vector3d centre = CameraCentre(truth.pose) * 1000;  // mm
  EXPECT_NEAR(answer["camera_centre"]["x"].get<double>(), centre.x(), 0.05);
  EXPECT_NEAR(answer["camera_centre"]["y"].get<double>(), centre.y(), 0.05);
  EXPECT_NEAR(answer["camera_centre"]["z"].get<double>(), centre.z(), 0.05);
  const json& path = answer["path"];
  ASSERT_GT(path.size(), 100u);
  int frames = 0;
  for (const auto& row : ReadCsv(*clip_ / "truth.csv")) {
    if (row.size() < 6 || row[4].empty()) continue;
    EXPECT_LT(DistanceToPath(std::stod(row[4]), std::stod(row[5]), path), 0.05) << "frame " << row[0];
    ++frames;
  }
  EXPECT_GT(frames, 5);
}

// Saving journals the scene file: atomic file, named in experiment.json (format 2), 409 for a
// stale version, undone like a row, and found again after a restart.
TEST_F(VideoApiTest, SavedSceneIsJournaledAndSurvivesARestart) {
  MakeClipExperiment();
  const std::int64_t version = Version();
  json body = {{"version", version}, {"video", "videos/clip.mp4"}, {"row", FirstRowId()},
               {"clicks", Clicks(ReadPoints(*clip_ / "points.csv"))}};
  auto [status, state] = Send("PUT", "/api/scenes/main", body);
  ASSERT_EQ(status, 200) << state.dump();
  EXPECT_EQ(state["experiment"]["scenes"]["main"], "calibration/scene-main.json");
  const SceneCalibration saved = ReadSceneFile((dir_ / "calibration" / "scene-main.json").string());
  const SceneCalibration truth = ReadSceneFile((*clip_ / "scene.json").string());
  EXPECT_LT((CameraCentre(saved.pose) - CameraCentre(truth.pose)).norm(), 5e-5);
  const json on_disk = json::parse(ReadBytes(dir_ / "experiment.json"));
  EXPECT_EQ(on_disk["format"], "uphill-experiment/2");
  EXPECT_EQ(on_disk["scenes"]["main"], "calibration/scene-main.json");
  // A second tab still at the old version.
  auto [stale, conflict] = Send("PUT", "/api/scenes/other", body);
  EXPECT_EQ(stale, 409);
  EXPECT_EQ(conflict["state"]["version"], version + 1);
  // The restart replays the journal: the scene is still named, and its file still there.
  Stop();
  Start();
  EXPECT_EQ(State()["experiment"]["scenes"]["main"], "calibration/scene-main.json");
  // Undo removes the name (the file of version N stays readable for whoever has it open).
  auto [undone, after] = Send("POST", "/api/undo", {{"version", Version()}});
  ASSERT_EQ(undone, 200) << after.dump();
  EXPECT_FALSE(after["experiment"].contains("scenes"));
}

// Degenerate clicks are refused with the rule, naming the clicks: fewer than four, and points
// all on one rail (one line in space).
TEST_F(VideoApiTest, DegenerateClicksAreRefusedWithTheRule) {
  MakeClipExperiment();
  std::vector<ClipPoint> points = ReadPoints(*clip_ / "points.csv");
  std::vector<ClipPoint> three(points.begin(), points.begin() + 3);
  auto [few, few_body] = Send("POST", "/api/scene/solve", {{"video", "videos/clip.mp4"}, {"clicks", Clicks(three)}});
  EXPECT_EQ(few, 422);
  EXPECT_EQ(few_body["field"], "clicks");
  EXPECT_NE(few_body["error"].get<std::string>().find("at least 4"), std::string::npos) << few_body.dump();
  std::vector<ClipPoint> left;
  for (const ClipPoint& p : points)
    if (p.name == "O" || p.name.find("left") != std::string::npos) left.push_back(p);
  left.erase(std::remove_if(left.begin(), left.end(), [](const ClipPoint& p) { return p.name == "left foot"; }), left.end());
  ASSERT_GE(left.size(), 4u);
  auto [line, line_body] = Send("POST", "/api/scene/solve", {{"video", "videos/clip.mp4"}, {"clicks", Clicks(left)}});
  EXPECT_EQ(line, 422);
  EXPECT_NE(line_body["error"].get<std::string>().find("one line"), std::string::npos) << line_body.dump();
}

// A camera calibrated for another size than the video's is named with both sizes.
TEST_F(VideoApiTest, CameraOfAnotherSizeIsRefused) {
  MakeClipExperiment();
  auto [status, body] = Send("POST", "/api/scene/solve",
                             {{"video", "videos/small.mp4"}, {"clicks", Clicks(ReadPoints(*clip_ / "points.csv"))}});
  EXPECT_EQ(status, 422);
  EXPECT_NE(body["error"].get<std::string>().find("320×180"), std::string::npos) << body.dump();
  EXPECT_NE(body["error"].get<std::string>().find("480×270"), std::string::npos) << body.dump();
}

// The frame is the video's own (decoded here by OpenCV directly), losslessly as PNG.
TEST_F(VideoApiTest, FrameIsTheVideosFrame) {
  MakeClipExperiment();
  auto r = client_->Get("/api/video/frame?video=videos/clip.mp4&frame=0");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/png");
  const cv::Mat served = cv::imdecode(std::vector<unsigned char>(r->body.begin(), r->body.end()), cv::IMREAD_COLOR);
  cv::VideoCapture capture((dir_ / "videos" / "clip.mp4").string(), cv::CAP_FFMPEG);
  cv::Mat direct;
  ASSERT_TRUE(capture.read(direct));
  ASSERT_EQ(served.size(), direct.size());
  EXPECT_EQ(cv::norm(served, direct, cv::NORM_INF), 0);
  auto beyond = client_->Get("/api/video/frame?video=videos/clip.mp4&frame=500");
  ASSERT_TRUE(beyond);
  EXPECT_EQ(beyond->status, 422);
  std::ofstream(dir_ / "videos" / "notes.mp4") << "not a video at all\n";
  auto bad = client_->Get("/api/video/frame?video=videos/notes.mp4");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 422);
  EXPECT_NE(bad->body.find("is not a video"), std::string::npos) << bad->body;
  auto outside = client_->Get("/api/video/frame?video=../clip.mp4");
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->status, 422);
}

// An upload lands whole (byte for byte) under videos/; one that is not a video, or too large, or
// cut off leaves nothing behind, not even its staging folder.
class UploadTest : public VideoApiTest {
 protected:
  void Configure(ServerOptions& options) override { options.max_upload_bytes = 1 << 20; }
  std::vector<std::string> Leftovers() {
    std::vector<std::string> out;
    if (!fs::exists(dir_ / "videos")) return out;
    for (const auto& e : fs::directory_iterator(dir_ / "videos")) out.push_back(e.path().filename().string());
    return out;
  }
};

TEST_F(UploadTest, UploadIsStoredWholeOrNotAtAll) {
  Start();
  Create();
  const std::string clip = ReadBytes(*clip_ / "clip.mp4");
  ASSERT_LT(clip.size(), 1u << 20);
  auto r = client_->Put("/api/videos/trial1.mp4", clip, "application/octet-stream");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json answer = json::parse(r->body);
  EXPECT_EQ(answer["path"], "videos/trial1.mp4");
  EXPECT_EQ(answer["width"], 480);
  EXPECT_EQ(ReadBytes(dir_ / "videos" / "trial1.mp4"), clip);
  EXPECT_EQ(Leftovers(), std::vector<std::string>{"trial1.mp4"});
  // The same name again: refused, the first file untouched.
  auto again = client_->Put("/api/videos/trial1.mp4", std::string("x"), "application/octet-stream");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 422);
  EXPECT_EQ(ReadBytes(dir_ / "videos" / "trial1.mp4"), clip);
  // Not a video.
  auto text = client_->Put("/api/videos/text.mp4", std::string(5000, 'a'), "application/octet-stream");
  ASSERT_TRUE(text);
  EXPECT_EQ(text->status, 422);
  EXPECT_NE(text->body.find("is not a video"), std::string::npos) << text->body;
  // Larger than the limit: refused before its body is read.
  // (The server answers and closes before the body: a client still sending it sees the close,
  // so the answer is read from a raw connection that sends the headers only.)
  const std::string big = "PUT /api/videos/big.mp4 HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port_) +
                          "\r\nContent-Type: application/octet-stream\r\nContent-Length: " +
                          std::to_string((1 << 20) + 1) + "\r\n\r\n";
  EXPECT_EQ(StatusOf(RawExchange(port_, big, std::chrono::milliseconds(2000))), 413);
  // Cut off: the connection closes after half of the declared bytes.
  const std::string head = "PUT /api/videos/cut.mp4 HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port_) +
                           "\r\nContent-Type: application/octet-stream\r\nContent-Length: " +
                           std::to_string(clip.size()) + "\r\n\r\n";
  const int cut = ConnectLoopback(port_);
  ASSERT_GE(cut, 0);
  const std::string half = head + clip.substr(0, clip.size() / 2);
  ASSERT_EQ(::send(cut, half.data(), half.size(), MSG_NOSIGNAL), static_cast<ssize_t>(half.size()));
  ::close(cut);
  // The event: the staging folder is gone (the server reads the close and cleans up). The server
  // may not have opened it yet when the socket closes: first its staging folder is let appear
  // (it may also come and go between two looks, hence the short limit, whose result is not
  // asserted), then it must be gone.
  WaitUntil([&] { return Leftovers() != std::vector<std::string>{"trial1.mp4"}; }, std::chrono::seconds(2));
  EXPECT_TRUE(WaitUntil([&] { return Leftovers() == std::vector<std::string>{"trial1.mp4"}; }));
  EXPECT_EQ(Leftovers(), std::vector<std::string>{"trial1.mp4"});
  // Only application/octet-stream is an upload.
  auto form = client_->Put("/api/videos/form.mp4", clip, "multipart/form-data");
  ASSERT_TRUE(form);
  EXPECT_EQ(form->status, 415);
}

// An upload request as sent by a client that does not wait for the answer before its body.
std::string UploadRequest(int port, const std::string& path, const std::string& body) {
  return "PUT " + path + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
         "\r\nContent-Type: application/octet-stream\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" +
         body;
}

// Guards: a PNG of 389 KB declaring 20,000 × 20,000 pixels was accepted as a view (13 of them took
// the calibration to 5.2 GB), an MJPEG AVI of 1.3 MB declaring 8,000 × 8,000 as a video. Truth: the
// limit of vision/decode_limits.hpp (60 million pixels; docs/serve.md "Limits") against the size
// each file declares (what ffprobe reads from the same bytes); a 4K video passes.
TEST_F(UploadTest, PicturesOverThePixelLimitAreRefusedBeforeDecoding) {
  Start();
  Create();
  auto view = client_->Put("/api/views/huge.png", PngDeclaring(20000, 20000), "application/octet-stream");
  ASSERT_TRUE(view);
  EXPECT_EQ(view->status, 422);
  EXPECT_NE(view->body.find("huge.png: an image of 20000 × 20000 pixels is more than uphill decodes: at most 60 "
                            "million pixels"),
            std::string::npos) << view->body;
  EXPECT_FALSE(fs::exists(dir_ / "calibration" / "views" / "huge.png"));
  const fs::path media = FreshFolder("oversized-media");
  WriteAviDeclaring(media / "huge.avi", 8000, 8000);
  auto video = client_->Put("/api/videos/huge.avi", ReadBytes(media / "huge.avi"), "application/octet-stream");
  ASSERT_TRUE(video);
  EXPECT_EQ(video->status, 422);
  EXPECT_NE(video->body.find("huge.avi: a video with frames of 8000 × 8000 pixels is more than uphill decodes"),
            std::string::npos) << video->body;
  EXPECT_EQ(Leftovers(), std::vector<std::string>{});
  WriteAviDeclaring(media / "uhd.avi", 3840, 2160);
  auto uhd = client_->Put("/api/videos/uhd.avi", ReadBytes(media / "uhd.avi"), "application/octet-stream");
  ASSERT_TRUE(uhd);
  EXPECT_EQ(uhd->status, 200) << uhd->body;
  // A view copied into a folder by hand: refused by the calibration, naming the file.
  fs::create_directories(dir_ / "copied");
  std::ofstream(dir_ / "copied" / "big.png", std::ios::binary) << PngDeclaring(20000, 20000);
  auto [status, answer] = Send("POST", "/api/camera/calibrate",
                               {{"version", State()["version"]}, {"folder", "copied"}, {"cols", 9}, {"rows", 6},
                                {"square", 20}});
  EXPECT_EQ(status, 422);
  EXPECT_NE(answer.value("error", "").find("copied/big.png: an image of 20000 × 20000 pixels"), std::string::npos)
      << answer.dump();
  fs::remove_all(media);
}

// Guards: a disk that filled during an upload answered 422, as if the file were wrong, where
// docs/serve.md's error table gives 500 for the server's own disk. Truth: that table. The full
// disk is played by RLIMIT_FSIZE: a write beyond it fails (EFBIG), as one on a full disk (ENOSPC).
TEST_F(UploadTest, ADiskThatFillsDuringAnUploadIs500AndLeavesNothing) {
  Start();
  Create();
  const std::string clip = ReadBytes(*clip_ / "clip.mp4");
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit full = old;
  full.rlim_cur = clip.size() / 2;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &full), 0);
  const std::string answer = RawExchange(port_, UploadRequest(port_, "/api/videos/full.mp4", clip), std::chrono::seconds(60));
  ::setrlimit(RLIMIT_FSIZE, &old);
  EXPECT_EQ(StatusOf(answer), 500) << answer;
  EXPECT_NE(answer.find("videos/full.mp4: cannot be written to the experiment folder's disk"), std::string::npos)
      << answer;
  EXPECT_EQ(Leftovers(), std::vector<std::string>{});
}

// Guards: a name holding %2F or %00, or longer than 120 characters, was answered 415 ("must be
// application/json") because the upload's route did not match it. Truth: the name's rule
// (docs/serve.md: 1 to 100 letters, digits, '.', '-', '_'), checked before the content type.
TEST_F(UploadTest, NamesThatBreakTheRuleAreRefusedByTheRule) {
  Start();
  Create();
  for (const std::string& name : {std::string("a%2Fb.mp4"), std::string("a%00b.mp4"), std::string(121, 'n') + ".mp4",
                                   std::string(101, 'n') + ".mp4"}) {
    const std::string answer = RawExchange(port_, UploadRequest(port_, "/api/videos/" + name, "x"), std::chrono::seconds(60));
    EXPECT_EQ(StatusOf(answer), 422) << name << ": " << answer;
    EXPECT_NE(answer.find("a file name of 1 to 100 letters, digits"), std::string::npos) << answer;
  }
  // The name is shown as sent: the decoded '/' and NUL as %2F and %00 again.
  const std::string slash = RawExchange(port_, UploadRequest(port_, "/api/videos/a%2Fb.mp4", "x"), std::chrono::seconds(60));
  EXPECT_NE(slash.find("(got \\\"a%2Fb.mp4\\\""), std::string::npos) << slash;
  EXPECT_EQ(Leftovers(), std::vector<std::string>{});
}

// Guards: a link at an intermediate folder answered 500 where a link at the file answered 422.
// Truth: docs/serve.md "What it reads and writes" (never through a link, at any level) and the
// rule that bad input is a 4xx: both are 422, naming the path.
TEST_F(VideoApiTest, LinksAtAnyLevelAre422) {
  MakeClipExperiment();
  fs::create_directory_symlink(dir_ / "videos", dir_ / "linked");
  fs::create_symlink(dir_ / "videos" / "clip.mp4", dir_ / "videos" / "leaf.mp4");
  const std::int64_t id = FirstRowId();
  for (const std::string video : {"linked/clip.mp4", "videos/leaf.mp4"}) {
    auto frame = client_->Get(("/api/video/frame?video=" + video + "&frame=0").c_str());
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->status, 422) << video << ": " << frame->body;
    EXPECT_NE(frame->body.find(video), std::string::npos) << frame->body;
    EXPECT_NE(frame->body.find("link"), std::string::npos) << frame->body;
    auto [status, answer] = Send("POST", "/api/rows/" + std::to_string(id) + "/video", {{"version", Version()}, {"video", video}});
    EXPECT_EQ(status, 422) << video << ": " << answer.dump();
  }
  fs::create_directory_symlink(dir_ / "videos", dir_ / "calibration" / "views");
  auto view = client_->Put("/api/views/a.png", PngDeclaring(16, 16), "application/octet-stream");
  ASSERT_TRUE(view);
  EXPECT_EQ(view->status, 422) << view->body;
  EXPECT_NE(view->body.find("symbolic link"), std::string::npos) << view->body;
  EXPECT_FALSE(fs::exists(dir_ / "videos" / "a.png"));
}

// Guards: `cols: 2147483648` was reported as "got -2147483648", `row=1e300` became row
// -9223372036854775808 and `row=1.9` row 1; marks off the rails were left out without a word.
// Truth: the rules as documented (a whole number in its range, reported as sent; a mark on the
// rails, 0 < x < L = 1000 mm for this clip's apparatus, calibration/README.md).
TEST_F(VideoApiTest, NumbersAreTakenAsSentAndMarksOffTheRailsAreRefused) {
  MakeClipExperiment();
  for (const std::string row : {"1e300", "1.9", "-1", "99999999999999999999"}) {
    auto r = client_->Get(("/api/scene/points?row=" + row).c_str());
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 422) << row;
    EXPECT_NE(r->body.find("row: must be a row id, a whole number from 1 to 999999999999 (got \\\"" + row + "\\\")"),
              std::string::npos) << r->body;
  }
  auto frame = client_->Get("/api/video/frame?video=videos/clip.mp4&frame=2147483648");
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->status, 422);
  EXPECT_NE(frame->body.find("(got \\\"2147483648\\\")"), std::string::npos) << frame->body;
  fs::create_directories(dir_ / "views");
  std::ofstream(dir_ / "views" / "a.png", std::ios::binary) << PngDeclaring(16, 16);
  for (const json& cols : {json(2147483648LL), json(2.5), json(-3)}) {
    auto [status, answer] = Send("POST", "/api/camera/calibrate",
                                 {{"version", Version()}, {"folder", "views"}, {"cols", cols}, {"rows", 6}, {"square", 20}});
    EXPECT_EQ(status, 422) << cols;
    EXPECT_EQ(answer.value("error", ""), "cols: must be the count of inner corners, a whole number from 2 to 100 (got " +
                                             cols.dump() + ")");
  }
  auto marks = client_->Get(("/api/scene/points?row=" + std::to_string(FirstRowId()) + "&marks=300,1500").c_str());
  ASSERT_TRUE(marks);
  EXPECT_EQ(marks->status, 422);
  EXPECT_NE(marks->body.find("marks: mark 2 at 1500 mm is not on the rails between O and the crossbar"), std::string::npos)
      << marks->body;
}

// Guards: OpenCV's assertions escaped as 500 for a square of 1e50 mm (and 1e308, 1e-50,
// 1e-300 mm) and for clicks 1e100 times too far from O. Truth: the ranges of
// vision/calibration.hpp, documented in docs/calibrate.md (a square 0.1 mm to 1 m, a point's
// coordinate within ±100 m of O): refused 422 naming the quantity, its value and the range.
TEST_F(VideoApiTest, CalibrationInputsOutOfRangeAre422) {
  MakeClipExperiment();
  fs::create_directories(dir_ / "views");
  std::ofstream(dir_ / "views" / "a.png", std::ios::binary) << PngDeclaring(16, 16);
  for (const double square : {1e50, 1e308, 1e-50, 1e-300}) {
    auto [status, answer] = Send("POST", "/api/camera/calibrate",
                                 {{"version", Version()}, {"folder", "views"}, {"cols", 9}, {"rows", 6}, {"square", square}});
    EXPECT_EQ(status, 422) << square << ": " << answer.dump();
    EXPECT_EQ(answer.value("field", ""), "square");
    EXPECT_NE(answer.value("error", "").find("is outside the allowed range 0.1 mm to 1000 mm"), std::string::npos)
        << answer.dump();
  }
  json clicks = Clicks(ReadPoints(*clip_ / "points.csv"));
  for (json& c : clicks)
    for (const char* k : {"x", "y", "z"}) c[k] = c[k].get<double>() * 1e100;
  auto [solve, solved] = Send("POST", "/api/scene/solve", {{"video", "videos/clip.mp4"}, {"clicks", clicks}});
  EXPECT_EQ(solve, 422) << solved.dump();
  EXPECT_NE(solved.value("error", "").find("is outside the allowed range -100000 mm to 100000 mm"), std::string::npos)
      << solved.dump();
  auto [save, saved] = Send("PUT", "/api/scenes/far", {{"version", Version()}, {"video", "videos/clip.mp4"}, {"clicks", clicks}});
  EXPECT_EQ(save, 422) << saved.dump();
}

// A frame request larger than the whole decode budget is refused at once. Guards: four concurrent
// frame requests of an 8000 × 8000 video took 2 GB. Truth: FrameDecodeBytes of a 480 × 270 frame,
// 480 · 270 · 6 bytes, is more than a budget of 1000 bytes.
class FrameBudgetTest : public VideoApiTest {
 protected:
  void Configure(ServerOptions& options) override { options.frame_decode_budget_bytes = 1000; }
};

TEST_F(FrameBudgetTest, AFrameLargerThanTheBudgetIs503) {
  MakeClipExperiment();
  auto r = client_->Get("/api/video/frame?video=videos/clip.mp4&frame=0");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503);
  EXPECT_NE(r->body.find("videos/clip.mp4: decoding it takes 760 KiB, more than the server's budget for decoding (1 KiB)"),
            std::string::npos) << r->body;
}

// The budget's arithmetic, with events: a decode that does not fit waits (its waiting is seen),
// and goes on when another returns its bytes; one larger than the whole budget never waits.
TEST(DecodeBudgetTest, ADecodeWaitsForTheBytesOthersReturn) {
  DecodeBudget budget(100);
  std::optional<DecodeBudget::Lease> first;
  first.emplace(budget.Acquire(60, std::chrono::milliseconds(0), "first"));
  EXPECT_EQ(budget.in_use(), 60u);
  EXPECT_THROW(budget.Acquire(50, std::chrono::milliseconds(0), "now"), DecodeBusy);
  std::future<std::size_t> second = std::async(std::launch::async, [&budget] {
    const DecodeBudget::Lease lease = budget.Acquire(50, std::chrono::minutes(10), "second");
    return budget.in_use();
  });
  ASSERT_TRUE(WaitUntil([&] { return budget.waiting() == 1; }));
  first.reset();
  EXPECT_EQ(second.get(), 50u);
  EXPECT_EQ(budget.in_use(), 0u);
  EXPECT_THROW(budget.Acquire(101, std::chrono::minutes(10), "too big"), DecodeBusy);
}

// Attaching a video: the row names it (measurements.csv gains `video`, the folder becomes format
// 2); a file that is not a video, or a video the saved scene does not fit, is refused.
TEST_F(VideoApiTest, AttachingChecksTheVideoAndTheScene) {
  MakeClipExperiment();
  const std::int64_t id = FirstRowId();
  auto [status, state] = Send("POST", "/api/rows/" + std::to_string(id) + "/video",
                              {{"version", Version()}, {"video", "videos/clip.mp4"}});
  ASSERT_EQ(status, 200) << state.dump();
  EXPECT_EQ(state["rows"][0]["video"], "videos/clip.mp4");
  EXPECT_NE(ReadBytes(dir_ / "measurements.csv").find("t1,,300,videos/clip.mp4,"), std::string::npos)
      << ReadBytes(dir_ / "measurements.csv");
  std::ofstream(dir_ / "videos" / "notes.mp4") << "not a video\n";
  auto [bad, bad_body] = Send("POST", "/api/rows/" + std::to_string(id) + "/video",
                              {{"version", Version()}, {"video", "videos/notes.mp4"}});
  EXPECT_EQ(bad, 422);
  EXPECT_NE(bad_body["error"].get<std::string>().find("is not a video"), std::string::npos);
  auto [saved, saved_state] = Send("PUT", "/api/scenes/main",
                                   {{"version", Version()}, {"video", "videos/clip.mp4"},
                                    {"clicks", Clicks(ReadPoints(*clip_ / "points.csv"))}});
  ASSERT_EQ(saved, 200) << saved_state.dump();
  auto [small, small_body] = Send("POST", "/api/rows/" + std::to_string(id) + "/video",
                                  {{"version", Version()}, {"video", "videos/small.mp4"}});
  EXPECT_EQ(small, 422);
  EXPECT_NE(small_body["error"].get<std::string>().find("scene"), std::string::npos) << small_body.dump();
  EXPECT_EQ(State()["rows"][0]["video"], "videos/clip.mp4");  // unchanged
}

// Tracking in the page (app/video_trials.hpp): a ball resting inside its rest band (μ = 0.05) is
// found where make_video drew it (truth.csv's x, the exact camera and pose as the experiment's),
// and its rest becomes the row's Y through the journal; a ball that rolls up and falls off has no
// rest to accept.
class TrackApiTest : public ServerFixture {
 protected:
  void SetUp() override {}
  void MakeTrial(const std::string& flags) {
    clip_ = FreshFolder("server-track-clip");
    ASSERT_EQ(std::system((std::string(UPHILL_MAKE_VIDEO) + " " + clip_.string() +
                           " --width 640 --height 360 --boards 0 --noise 1 --mu 0.05 " + flags + " > /dev/null").c_str()),
              0);
    fs::create_directories(dir_ / "calibration");
    fs::create_directories(dir_ / "videos");
    fs::copy_file(clip_ / "cam.json", dir_ / "calibration" / "camera.json");
    fs::copy_file(clip_ / "scene.json", dir_ / "calibration" / "scene-main.json");
    fs::copy_file(clip_ / "clip.mp4", dir_ / "videos" / "t1.mp4");
    const json experiment = {{"format", "uphill-experiment/2"},
                             {"body", {{"type", "sphere"}, {"R", "25.4 mm"}}},
                             {"apparatus", {{"L", "1000 mm"}, {"H", "100 mm"}, {"D", "150 mm"}, {"rod_diameter", "8 mm"}}},
                             {"camera", "calibration/camera.json"},
                             {"scenes", {{"main", "calibration/scene-main.json"}}}};
    std::ofstream(dir_ / "experiment.json") << experiment.dump(2);
    std::ofstream(dir_ / "measurements.csv") << "trial,series,Y_mm,video,note\nt1,,,videos/t1.mp4,\n";
    Start();
  }
  void TearDown() override {
    ServerFixture::TearDown();
    fs::remove_all(clip_);
  }
  fs::path clip_;
};

TEST_F(TrackApiTest, RestPositionBecomesY) {
  MakeTrial("--x0-band -0.02 --seconds 1");
  const std::int64_t id = State()["rows"][0]["id"];
  auto [status, track] = Send("POST", "/api/rows/" + std::to_string(id) + "/track", json::object());
  ASSERT_EQ(status, 200) << track.dump();
  EXPECT_EQ(track["frames_tracked"], track["frames"]);
  EXPECT_GE(track["strip"].size(), 4u);
  const auto truth = ReadCsv(clip_ / "truth.csv");
  const double drawn = std::stod(truth.back()[2]);  // mm
  ASSERT_TRUE(track["rest"].is_object()) << track.dump();
  EXPECT_NEAR(track["rest"]["y"]["value"].get<double>(), drawn, 0.5);
  // The outline on the strip is where the ball was drawn (truth.csv's pixels of its centre).
  for (const json& f : track["strip"]) {
    const auto& row = truth.at(f["frame"].get<std::size_t>());
    EXPECT_NEAR(f["u"].get<double>(), std::stod(row[4]), 0.5);
    EXPECT_NEAR(f["v"].get<double>(), std::stod(row[5]), 0.5);
    // With its standard uncertainty along the rails (the track CSV's u_x, in the experiment's unit).
    EXPECT_GT(f["u_x"].get<double>(), 0.0);
    EXPECT_LT(f["u_x"].get<double>(), 0.5);
  }
  auto [accepted, state] = Send("POST", "/api/rows/" + std::to_string(id) + "/accept-y", {{"version", State()["version"]}});
  ASSERT_EQ(accepted, 200) << state.dump();
  EXPECT_NEAR(std::stod(state["rows"][0]["Y"].get<std::string>()), track["rest"]["y"]["value"].get<double>(), 1e-3);
  EXPECT_FALSE(state["rows"][0]["u_Y"].get<std::string>().empty());
  Stop();
  Start();
  EXPECT_EQ(State()["rows"][0]["Y"], state["rows"][0]["Y"]);

  // The typed Y against the video's, by the report's rule (|typed − video| > 3σ, σ the combined
  // standard uncertainty): the accepted Y agrees; one typed 40 mm off (the recording of another
  // setting attached to the trial) is flagged, with a warning, before it could be accepted.
  auto [again_status, again] = Send("POST", "/api/rows/" + std::to_string(id) + "/track", json::object());
  ASSERT_EQ(again_status, 200) << again.dump();
  ASSERT_TRUE(again["typed_y"].is_object()) << again.dump();
  EXPECT_FALSE(again["typed_y"]["flagged"].get<bool>());
  EXPECT_NEAR(again["typed_y"]["difference"].get<double>(), 0, 1e-3);
  json off = State()["rows"][0];
  off.erase("check");
  off.erase("id");
  off["Y"] = std::to_string(std::stod(off["Y"].get<std::string>()) + 40);
  auto [edited, edited_state] = Send("PUT", "/api/rows/" + std::to_string(id), {{"version", State()["version"]}, {"row", off}});
  ASSERT_EQ(edited, 200) << edited_state.dump();
  auto [flagged_status, flagged] = Send("POST", "/api/rows/" + std::to_string(id) + "/track", json::object());
  ASSERT_EQ(flagged_status, 200) << flagged.dump();
  EXPECT_TRUE(flagged["typed_y"]["flagged"].get<bool>()) << flagged.dump();
  EXPECT_NEAR(flagged["typed_y"]["difference"].get<double>(), 40, 1e-3);
  bool warned = false;
  for (const json& w : flagged["warnings"]) warned |= w.get<std::string>().find("differ by 40") != std::string::npos;
  EXPECT_TRUE(warned) << flagged["warnings"].dump();
}

TEST_F(TrackApiTest, NoRestNoY) {
  MakeTrial("--x0-band 0.3 --release-time 0.3 --until-end");
  const std::int64_t id = State()["rows"][0]["id"];
  auto [status, body] = Send("POST", "/api/rows/" + std::to_string(id) + "/accept-y", {{"version", State()["version"]}});
  EXPECT_EQ(status, 422);
  EXPECT_NE(body["error"].get<std::string>().find("never comes to rest"), std::string::npos) << body.dump();
  EXPECT_TRUE(State()["rows"][0]["Y"].is_null());
}

// The camera from chessboard views in the folder: make_video's views of its exact camera give
// that camera back (fx within 1 %), with the verdict and the views used; the file is journaled.
class CameraCalibrationTest : public ServerFixture {};

TEST_F(CameraCalibrationTest, ViewsInTheFolderGiveTheCamera) {
  Create();
  const fs::path clip = FreshFolder("server-camera-views");
  ASSERT_EQ(std::system((std::string(UPHILL_MAKE_VIDEO) + " " + clip.string() +
                         " --width 640 --height 360 --frames 1 --boards 12 > /dev/null").c_str()),
            0);
  fs::create_directories(dir_ / "calibration");
  fs::copy(clip / "boards", dir_ / "calibration" / "views");
  const CameraIntrinsics truth = ReadCameraFile((clip / "cam.json").string());
  fs::remove_all(clip);
  auto r = client_->Post("/api/camera/calibrate",
                         json{{"version", State()["version"]}, {"folder", "calibration/views"}, {"cols", 9}, {"rows", 6}, {"square", 20}}.dump(),
                         kJson);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json answer = json::parse(r->body);
  EXPECT_NEAR(answer["calibration"]["fx"].get<double>(), truth.fx, 0.01 * truth.fx);
  EXPECT_NEAR(answer["calibration"]["cx"].get<double>(), truth.cx, 3);
  EXPECT_GE(answer["calibration"]["views_used"].get<int>(), 8);
  EXPECT_EQ(answer["state"]["experiment"]["camera"], "calibration/camera.json");
  const CameraIntrinsics saved = ReadCameraFile((dir_ / "calibration" / "camera.json").string());
  EXPECT_DOUBLE_EQ(saved.fx, answer["calibration"]["fx"].get<double>());
  auto [missing, body] = Send("POST", "/api/camera/calibrate", {{"version", State()["version"]}, {"folder", "nothing"}});
  EXPECT_EQ(missing, 422);
  EXPECT_EQ(body["field"], "folder");
}

// Chessboard views uploaded from the page (PUT /api/views/NAME) land whole in calibration/views,
// the folder the camera calibration reads, and give the camera back as views copied into the
// folder do. Truth: the camera (cam.json) with which make_video rendered the views (the
// project's chessboard renderer, vision/chessboard_render.hpp); files compared byte for byte. A
// file that does not decode as an image (named, with the rule), a name without an image
// extension, a name taken and a view over the limit are refused and leave nothing behind, not
// even a staging folder. The camera file goes through the journal: a stale version is 409, and
// a restarted server finds it.
class ViewUploadTest : public CameraCalibrationTest {
 protected:
  void Configure(ServerOptions& options) override { options.max_view_upload_bytes = 1 << 20; }
  std::vector<std::string> Views() {
    std::vector<std::string> out;
    if (!fs::exists(dir_ / "calibration" / "views")) return out;
    for (const auto& e : fs::directory_iterator(dir_ / "calibration" / "views")) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

TEST_F(ViewUploadTest, UploadedViewsGiveTheCamera) {
  Create();
  const fs::path clip = FreshFolder("server-camera-upload");
  ASSERT_EQ(std::system((std::string(UPHILL_MAKE_VIDEO) + " " + clip.string() +
                         " --width 640 --height 360 --frames 1 --boards 12 > /dev/null").c_str()),
            0);
  const CameraIntrinsics truth = ReadCameraFile((clip / "cam.json").string());
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(clip / "boards")) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names.size(), 12u);
  for (const std::string& name : names) {
    const std::string bytes = ReadBytes(clip / "boards" / name);
    ASSERT_LT(bytes.size(), 1u << 20);
    auto r = client_->Put(("/api/views/" + name).c_str(), bytes, "application/octet-stream");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
    const json answer = json::parse(r->body);
    EXPECT_EQ(answer["path"], "calibration/views/" + name);
    EXPECT_EQ(answer["width"], 640);
    EXPECT_EQ(answer["height"], 360);
    EXPECT_EQ(ReadBytes(dir_ / "calibration" / "views" / name), bytes);
  }
  EXPECT_EQ(Views(), names);

  // Refused, each leaving the folder as it was.
  const std::string first = ReadBytes(clip / "boards" / names[0]);
  auto text = client_->Put("/api/views/notes.png", std::string(5000, 'a'), "application/octet-stream");
  ASSERT_TRUE(text);
  EXPECT_EQ(text->status, 422);
  EXPECT_NE(text->body.find("notes.png: not an image OpenCV can decode (a chessboard view must be a PNG, JPEG"),
            std::string::npos) << text->body;
  auto named = client_->Put("/api/views/board.txt", first, "application/octet-stream");
  ASSERT_TRUE(named);
  EXPECT_EQ(named->status, 422);
  EXPECT_NE(named->body.find("board.txt: not an image file name (.png, .jpg, .jpeg, .bmp, .tif, .tiff)"),
            std::string::npos) << named->body;
  auto taken = client_->Put(("/api/views/" + names[0]).c_str(), std::string("x"), "application/octet-stream");
  ASSERT_TRUE(taken);
  EXPECT_EQ(taken->status, 422);
  EXPECT_EQ(ReadBytes(dir_ / "calibration" / "views" / names[0]), first);
  const std::string big = "PUT /api/views/big.png HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port_) +
                          "\r\nContent-Type: application/octet-stream\r\nContent-Length: " +
                          std::to_string((1 << 20) + 1) + "\r\n\r\n";
  EXPECT_EQ(StatusOf(RawExchange(port_, big, std::chrono::milliseconds(2000))), 413);
  EXPECT_EQ(Views(), names);

  // The calibration from the uploaded views: through the journal, version conflicts refused.
  const json calibrate{{"folder", "calibration/views"}, {"cols", 9}, {"rows", 6}, {"square", 20}};
  const std::int64_t version = State()["version"];
  json stale = calibrate;
  stale["version"] = version - 1;
  auto [conflict, refused] = Send("POST", "/api/camera/calibrate", stale);
  EXPECT_EQ(conflict, 409) << refused.dump();
  EXPECT_FALSE(fs::exists(dir_ / "calibration" / "camera.json"));
  json current = calibrate;
  current["version"] = version;
  auto [status, answer] = Send("POST", "/api/camera/calibrate", current);
  ASSERT_EQ(status, 200) << answer.dump();
  // make_video's views keep the board near the middle: the verdict says so, with its reason.
  EXPECT_EQ(answer["calibration"]["verdict"], "poor");
  ASSERT_EQ(answer["calibration"]["reasons"].size(), 1u);
  EXPECT_NE(answer["calibration"]["reasons"][0].get<std::string>().find("the corners cover only"), std::string::npos)
      << answer["calibration"]["reasons"].dump();
  EXPECT_NEAR(answer["calibration"]["fx"].get<double>(), truth.fx, 0.01 * truth.fx);
  EXPECT_NEAR(answer["calibration"]["fy"].get<double>(), truth.fy, 0.01 * truth.fy);
  EXPECT_NEAR(answer["calibration"]["cx"].get<double>(), truth.cx, 3);
  EXPECT_NEAR(answer["calibration"]["cy"].get<double>(), truth.cy, 3);
  EXPECT_EQ(answer["calibration"]["views_used"].get<int>(), 12);
  Stop();
  Start();
  EXPECT_EQ(State()["experiment"]["camera"], "calibration/camera.json");
  EXPECT_DOUBLE_EQ(ReadCameraFile((dir_ / "calibration" / "camera.json").string()).fx,
                   answer["calibration"]["fx"].get<double>());
  fs::remove_all(clip);
}

}  // namespace
}  // namespace uphill::testing
