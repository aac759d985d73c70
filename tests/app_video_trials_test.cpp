// The video trials of an experiment folder (app/video_trials.hpp): tracked, analysed, cached, and
// carried into the fit report. Truth: tools/make_video's renderer (synthetic_clip.hpp), whose
// ground truth is exact: the body's true rest position (truth CSV) and the μ the clip's motion was
// made with. Clips are small (640 × 360, ~1–2 s) to keep the suite fast.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <sstream>
#include <thread>

#include "app/video_trials.hpp"
#include "file_test_support.hpp"
#include "io/experiment.hpp"
#include "report/fit_document.hpp"
#include "report/fit_json.hpp"
#include "report/report_outputs.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

// make_video into `dir` (clip `name`, 640 × 360, D = 150 mm, the default camera).
void MakeClip(const fs::path& dir, const std::string& name, const std::string& flags) {
  const std::string command = std::string(UPHILL_MAKE_VIDEO) + " " + dir.string() +
                              " --width 640 --height 360 --boards 0 --name " + name + " " + flags + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
}

// x (m) of the first frame of make_video's truth CSV (header frame,t,x,z,u,v,visibility; x in mm).
double TrueFirstX(const fs::path& truth_csv) {
  std::ifstream in(truth_csv);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  std::stringstream cells(line);
  std::string frame, t, x;
  std::getline(cells, frame, ',');
  std::getline(cells, t, ',');
  std::getline(cells, x, ',');
  return std::stod(x) * 1e-3;
}

long MtimeNs(const fs::path& p) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) return -1;
  return st.st_mtim.tv_sec * 1000000000L + st.st_mtim.tv_nsec;
}

// Sets an environment variable for the scope, restoring it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) ::setenv(name_, old_->c_str(), 1);
    else ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// The cache entries (folders) directly in `cache`, and any staging folder left there.
std::vector<fs::path> Entries(const fs::path& cache) {
  std::vector<fs::path> out;
  if (!fs::is_directory(cache)) return out;
  for (const auto& e : fs::directory_iterator(cache)) out.push_back(e.path());
  return out;
}

// Every number of a JSON document replaced by `value` (booleans and text kept).
void SetEveryNumber(nlohmann::json* j, double value) {
  if (j->is_number()) *j = value;
  if (!j->is_structured()) return;
  for (auto& child : *j) SetEveryNumber(&child, value);
}

constexpr double kMu = 0.05;

class VideoTrials : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshFolder("video-trials"));
    const fs::path clips = *dir_ / "clips";
    // At rest just inside the far edge of μ's rest band for the whole clip; and released at rest
    // beyond the band, so that it rolls up and falls off (its motion gives μ).
    MakeClip(clips, "rest", "--mu 0.05 --x0-band -0.02 --seconds 1");
    MakeClip(clips, "roll", "--mu 0.05 --x0-band 0.3 --release-time 0.5 --until-end");
    fs::create_directories(*dir_ / "calibration");
    fs::create_directories(*dir_ / "videos");
    fs::copy_file(clips / "cam.json", *dir_ / "calibration" / "camera.json");
    fs::copy_file(clips / "scene.json", *dir_ / "calibration" / "scene-main.json");
    fs::copy_file(clips / "rest.mp4", *dir_ / "videos" / "rest.mp4");
    fs::copy_file(clips / "roll.mp4", *dir_ / "videos" / "roll.mp4");
    std::ofstream(*dir_ / "videos" / "text.mp4") << "this is not a video\n";
    std::ofstream(*dir_ / "experiment.json") << R"({"format": "uphill-experiment/2",
      "body": {"type": "sphere", "R": "25.4 mm"},
      "apparatus": {"L": "1000 mm", "H": "100 mm", "rod_diameter": "8 mm"},
      "uncertainties": {"L": "1 mm", "H": "0.5 mm", "D": "0.2 mm", "Y": "0.5 mm"},
      "camera": "calibration/camera.json", "scenes": {"main": "calibration/scene-main.json"},
      "video_analysis": {"fit": "mu", "u_x": "0.3 mm"}})";
    // Rows: Y from the video; Y typed (the true far edge, far from the rest clip's x0 by design
    // only in the roll trial); a file that is not a video; a row without video.
    std::ofstream(*dir_ / "measurements.csv") << "trial,D_mm,Y_mm,video\n"
                                                 "rest,150,,videos/rest.mp4\n"
                                                 "roll,150,351.2,videos/roll.mp4\n"
                                                 "bad,150,,videos/text.mp4\n"
                                                 "typed,160,330,\n";
    true_rest_ = TrueFirstX(clips / "rest.truth.csv");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  // A copy of the experiment (files, calibration, videos; no cache) in a fresh folder.
  static fs::path CopyExperiment(const std::string& name) {
    const fs::path copy = FreshFolder(name);
    for (const char* f : {"experiment.json", "measurements.csv"}) fs::copy_file(*dir_ / f, copy / f);
    for (const char* d : {"calibration", "videos"}) fs::copy(*dir_ / d, copy / d, fs::copy_options::recursive);
    return copy;
  }
  // The rest trial (the first row, a short clip) of the folder, and whether it was served from a
  // cache entry (the progress said kCached) rather than tracked.
  static std::pair<VideoTrial, bool> RestTrial(const fs::path& folder) {
    const Experiment experiment = LoadExperiment(folder.string());
    bool cached = false;
    VideoTrial t = TrackTrialVideo(experiment, experiment.rows[0], 0, [&](const VideoProgress& p) {
      cached |= p.stage == VideoProgress::Stage::kCached;
    });
    EXPECT_EQ(cached, t.from_cache);
    return {t, cached};
  }
  static inline fs::path* dir_ = nullptr;
  static inline double true_rest_ = 0;
};

TEST_F(VideoTrials, RestPositionFromTheVideoMatchesTheTruthAndABadTrialStopsNothing) {
  const Experiment experiment = LoadExperiment(dir_->string());
  ASSERT_EQ(VideoRows(experiment).size(), 3u);
  std::vector<VideoProgress::Stage> last(3, VideoProgress::Stage::kQueued);
  const std::vector<VideoTrial> trials = TrackExperimentVideos(experiment, 2, [&](const VideoProgress& p) {
    ASSERT_LT(p.index, 3u);
    last[p.index] = p.stage;
  });
  ASSERT_EQ(trials.size(), 3u);
  // The rest clip: Y within its stated u of the renderer's true position.
  const VideoTrial& rest = trials[0];
  ASSERT_TRUE(rest.error.empty()) << rest.error << " / " << trials[1].error;
  ASSERT_TRUE(rest.rest.has_value());
  ASSERT_TRUE(rest.rest->u.has_value());
  EXPECT_NEAR(rest.rest->value, true_rest_, *rest.rest->u) << "u(Y) = " << *rest.rest->u;
  EXPECT_LT(*rest.rest->u, 1e-3);
  EXPECT_EQ(last[0], VideoProgress::Stage::kDone);
  // The roll clip: released at x0 beyond the band, falls off; μ of its motion within 4 standard
  // errors of the μ it was made with (track_analysis.hpp states pulls of RMS ~1).
  const VideoTrial& roll = trials[1];
  ASSERT_TRUE(roll.error.empty()) << roll.error;
  EXPECT_FALSE(roll.rest.has_value());
  ASSERT_TRUE(roll.fit_available) << roll.fit_unavailable;
  EXPECT_EQ(roll.fitted, "mu");
  ASSERT_TRUE(roll.fit_value && roll.fit_value->u);
  EXPECT_NEAR(roll.fit_value->value, kMu, 4 * *roll.fit_value->u + 1e-4) << "u = " << *roll.fit_value->u;
  ASSERT_TRUE(roll.release_t.has_value());
  EXPECT_NEAR(roll.release_t->value, 0.5, 4 * roll.release_t->u.value_or(0) + 1.0 / 30);
  // Not a video: that trial's error names it and its file; the others were analysed.
  const VideoTrial& bad = trials[2];
  EXPECT_NE(bad.error.find("trial 'bad' (videos/text.mp4)"), std::string::npos) << bad.error;
  EXPECT_EQ(last[2], VideoProgress::Stage::kFailed);
}

// One job at a time: the trials are started largest file first and each is handed to the done
// callback once, with its index into VideoRows. Truth: the files' sizes as the file system states
// them, and the rows of measurements.csv.
TEST_F(VideoTrials, LargestVideoFirstAndEachTrialHandedOverOnce) {
  const Experiment experiment = LoadExperiment(dir_->string());
  const std::vector<const ExperimentRow*> rows = VideoRows(experiment);
  std::vector<std::size_t> expected = {0, 1, 2};
  std::stable_sort(expected.begin(), expected.end(), [&](std::size_t a, std::size_t b) {
    return fs::file_size(*dir_ / rows[a]->video) > fs::file_size(*dir_ / rows[b]->video);
  });
  // The roll clip (longer) is larger than the rest clip: the order differs from the rows'.
  ASSERT_NE(expected, (std::vector<std::size_t>{0, 1, 2}));
  std::vector<std::size_t> order;
  const std::vector<VideoTrial> trials =
      TrackExperimentVideos(experiment, 1, {}, [&](std::size_t index, const VideoTrial& trial) {
        ASSERT_LT(index, rows.size());
        EXPECT_EQ(trial.trial, rows[index]->trial);
        order.push_back(index);
      });
  EXPECT_EQ(order, expected);
  ASSERT_EQ(trials.size(), 3u);
  for (std::size_t i = 0; i < trials.size(); ++i) EXPECT_EQ(trials[i].trial, rows[i]->trial);
}

TEST_F(VideoTrials, SecondRunReadsTheCacheOnly) {
  const Experiment experiment = LoadExperiment(dir_->string());
  const std::vector<VideoTrial> first = TrackExperimentVideos(experiment, 1);
  // Every cache entry's track.csv, with its modification time.
  std::map<fs::path, long> mtimes;
  for (const auto& entry : fs::directory_iterator(*dir_ / ".uphill-cache" / "video"))
    mtimes[entry.path()] = MtimeNs(entry.path() / "track.csv");
  ASSERT_EQ(mtimes.size(), 2u);  // the two good videos
  std::vector<VideoProgress::Stage> stages;
  const std::vector<VideoTrial> second = TrackExperimentVideos(experiment, 2, [&](const VideoProgress& p) {
    if (p.stage == VideoProgress::Stage::kTracking && p.index < 2) stages.push_back(p.stage);  // 2: not a video
  });
  EXPECT_TRUE(stages.empty()) << "a video was tracked again";
  ASSERT_EQ(second.size(), 3u);
  EXPECT_TRUE(second[0].from_cache);
  EXPECT_TRUE(second[1].from_cache);
  EXPECT_FALSE(second[2].error.empty());
  EXPECT_EQ(VideoTrialToJson(second[0]).dump(), [&] {
    VideoTrial t = first[0];
    t.from_cache = true;
    return VideoTrialToJson(t).dump();
  }());
  for (const auto& [path, mtime] : mtimes) EXPECT_EQ(MtimeNs(path / "track.csv"), mtime) << path;

  // A changed analysis option is another key: tracked again, the old entries stay.
  Experiment g = experiment;
  g.video_analysis.fit = "g";
  const std::vector<VideoTrial> third = TrackExperimentVideos(g, 2);
  EXPECT_FALSE(third[0].from_cache);
  EXPECT_EQ(third[1].fitted, "g");
}

TEST_F(VideoTrials, TheReportUsesTheVideoYAndComparesTypedOnes) {
  Experiment experiment = LoadExperiment(dir_->string());
  const std::vector<VideoTrial> trials = TrackExperimentVideos(experiment, 2);
  AnalysisOptions options;
  options.mc_trials = 1000;
  const ExperimentAnalysis a = AnalyseExperimentWithVideos(&experiment, trials, options);
  // Rows: rest (Y from its video), roll (typed), typed; the bad video's row has no Y: left out
  // with the video's error.
  ASSERT_EQ(a.rows.size(), 3u);
  EXPECT_NEAR(a.rows[0].y, trials[0].rest->value, 0.0);
  EXPECT_NEAR(a.rows[0].u_y, *trials[0].rest->u, 0.0);
  EXPECT_DOUBLE_EQ(a.rows[1].y, 0.3512);
  bool bad_named = false;
  for (const std::string& e : a.row_errors) bad_named |= e.find("trial 'bad' (videos/text.mp4)") != std::string::npos;
  EXPECT_TRUE(bad_named);
  const std::string text = RenderText(FitDocument(a, false));
  EXPECT_NE(text.find("Rest positions from the videos"), std::string::npos);
  EXPECT_NE(text.find("Motion fits"), std::string::npos);
  EXPECT_NE(text.find("μ from the motions: "), std::string::npos);
  const auto json = AnalysisToJson(a);
  ASSERT_TRUE(json.contains("video_trials"));
  EXPECT_EQ(json.at("video_trials").size(), 3u);
  EXPECT_NEAR(json.at("motion_mu").at("mu").get<double>(), trials[1].fit_value->value, 1e-15);
}

TEST(VideoTrialsReport, CompareYFlagsBeyondThreeSigma) {
  // Truth: the rule |typed − video| > 3·sqrt(u_typed² + u_video²), by hand.
  EXPECT_FALSE(CompareY(0.300, 0.0003, 0.300, 0.0004).flagged);
  EXPECT_FALSE(CompareY(0.3014, 0.0003, 0.300, 0.0004).flagged);  // 1.4 mm < 3 × 0.5 mm
  EXPECT_TRUE(CompareY(0.3016, 0.0003, 0.300, 0.0004).flagged);   // 1.6 mm > 1.5 mm
  EXPECT_DOUBLE_EQ(CompareY(0.3016, 0.0003, 0.300, 0.0004).sigma, 0.0005);
}

TEST(VideoTrialsReport, WeightedMotionMuIsTheInverseVarianceMean) {
  // Truth: closed form. μ = (0.04/0.01² + 0.06/0.02²)/(1/0.01² + 1/0.02²) = 0.044, u = 1/sqrt(12500).
  std::vector<VideoTrial> trials(3);
  for (auto& t : trials) t.fit_available = true, t.fitted = "mu";
  trials[0].fit_value = Estimate{0.04, 0.01};
  trials[1].fit_value = Estimate{0.06, 0.02};
  trials[2].fit_value = Estimate{0.5, 0.01};
  trials[2].error = "failed";  // left out
  const auto m = WeightedMotionMu(trials);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->trials, 2);
  EXPECT_NEAR(m->mu, 0.044, 1e-15);
  EXPECT_NEAR(m->u, 1.0 / std::sqrt(12500.0), 1e-15);
  // χ² = (0.004/0.01)² + (0.016/0.02)² = 0.16 + 0.64, ν = 1.
  EXPECT_NEAR(*m->reduced_chi2, 0.8, 1e-12);
}

// Guards: parallel `uphill fit --jobs 1` runs of one fresh folder failed 1 in 2 with "cannot
// rename .staging-… to it: File exists" when two finished the same entry. Four threads fill the
// same entry at once: each waits (an event, not a time) until all four have missed the cache and
// tracked, so all four commit together. Truth: every thread succeeds, with the same numbers, and
// one entry is left, with no staging folder.
TEST_F(VideoTrials, RunsFillingTheSameEntryAtOnceAllSucceedWithTheSameNumbers) {
  const fs::path folder = CopyExperiment("parallel-fill");
  const Experiment experiment = LoadExperiment(folder.string());
  constexpr int kRuns = 4;
  std::mutex m;
  std::condition_variable cv;
  int analysing = 0;
  std::vector<VideoTrial> trials(kRuns);
  std::vector<std::thread> threads;
  for (int i = 0; i < kRuns; ++i)
    threads.emplace_back([&, i] {
      trials[i] = TrackTrialVideo(experiment, experiment.rows[0], 0, [&](const VideoProgress& p) {
        if (p.stage != VideoProgress::Stage::kAnalysing) return;
        std::unique_lock lock(m);
        ++analysing;
        cv.notify_all();
        cv.wait(lock, [&] { return analysing >= kRuns; });
      });
    });
  for (std::thread& t : threads) t.join();
  ASSERT_EQ(analysing, kRuns) << "a run did not track";
  for (int i = 0; i < kRuns; ++i) {
    ASSERT_TRUE(trials[i].error.empty()) << trials[i].error;
    ASSERT_TRUE(trials[i].rest.has_value());
    EXPECT_EQ(trials[i].rest->value, trials[0].rest->value);
    EXPECT_EQ(trials[i].rest->u, trials[0].rest->u);
    EXPECT_EQ(trials[i].frames, trials[0].frames);
  }
  const std::vector<fs::path> entries = Entries(folder / ".uphill-cache" / "video");
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].filename().string().size(), 32u) << entries[0];
  fs::remove_all(folder);
}

// Guards: a cache entry whose numbers were all set to 1e308 was trusted, and `fit` printed
// "inf ± inf". The entry is input: checked as any input (keys, types, finite and in range), and a
// damaged one is tracked again and replaced, with a one-line note. Truth: the first run's results.
TEST_F(VideoTrials, ADamagedCacheEntryIsTrackedAgainAndReplaced) {
  const fs::path folder = CopyExperiment("damaged-entry");
  const VideoTrial first = RestTrial(folder).first;
  ASSERT_TRUE(first.error.empty()) << first.error;
  const std::vector<fs::path> entries = Entries(folder / ".uphill-cache" / "video");
  ASSERT_EQ(entries.size(), 1u);
  const fs::path trial_json = entries[0] / "trial.json";
  nlohmann::json doc = nlohmann::json::parse(ReadBytes(trial_json));
  SetEveryNumber(&doc, 1e308);
  std::ofstream(trial_json) << doc.dump();
  const auto [second, second_cached] = RestTrial(folder);
  EXPECT_FALSE(second_cached);
  ASSERT_TRUE(second.error.empty()) << second.error;
  EXPECT_NE(second.cache_note.find("damaged"), std::string::npos) << second.cache_note;
  EXPECT_EQ(std::count(second.cache_note.begin(), second.cache_note.end(), '\n'), 0);
  EXPECT_EQ(VideoTrialToJson(second).dump(), VideoTrialToJson(first).dump());
  // Replaced: the next run reads it.
  const auto [third, third_cached] = RestTrial(folder);
  EXPECT_TRUE(third_cached);
  EXPECT_TRUE(third.cache_note.empty()) << third.cache_note;
  EXPECT_EQ(third.rest->value, first.rest->value);
  fs::remove_all(folder);
}

// Guards: a read-only experiment folder lost every video trial (.uphill-cache could not be made).
// A file where the cache folder should be stands for it (permission bits do not stop root): the
// entries go into $XDG_CACHE_HOME/uphill/video, and with no user cache either the trial is tracked
// without caching, its temporary folder removed. Truth: the entries on disk, the trial's numbers.
TEST_F(VideoTrials, AFolderThatCannotHoldItsCacheUsesTheUsersOrNone) {
  const fs::path folder = CopyExperiment("unwritable-cache");
  std::ofstream(folder / ".uphill-cache") << "in the way\n";
  const fs::path elsewhere = FreshFolder("unwritable-cache-user");
  {
    const ScopedEnv xdg("XDG_CACHE_HOME", (elsewhere / "xdg").string());
    const auto [first, first_cached] = RestTrial(folder);
    ASSERT_TRUE(first.error.empty()) << first.error;
    EXPECT_FALSE(first_cached);
    EXPECT_EQ(Entries(elsewhere / "xdg" / "uphill" / "video").size(), 1u);
    const auto [second, second_cached] = RestTrial(folder);
    EXPECT_TRUE(second_cached);
    EXPECT_EQ(second.rest->value, first.rest->value);
  }
  std::ofstream(elsewhere / "afile") << "x\n";
  fs::create_directories(elsewhere / "tmp");
  const ScopedEnv xdg("XDG_CACHE_HOME", (elsewhere / "afile" / "xdg").string());
  const ScopedEnv home("HOME", (elsewhere / "afile" / "home").string());
  const ScopedEnv tmp("TMPDIR", (elsewhere / "tmp").string());
  const auto [none, none_cached] = RestTrial(folder);
  ASSERT_TRUE(none.error.empty()) << none.error;
  EXPECT_FALSE(none_cached);
  EXPECT_TRUE(none.rest.has_value());
  EXPECT_TRUE(Entries(elsewhere / "tmp").empty());
  EXPECT_EQ(ReadBytes(folder / ".uphill-cache"), "in the way\n");
  fs::remove_all(elsewhere);
  fs::remove_all(folder);
}

// The cache's content key (data/README.md, "The video cache"): a video replaced by other bytes of
// the same size and modification time, a changed camera file, a changed scene file: each is
// tracked again, never served from the old entry. Truth: the progress (kCached or not).
TEST_F(VideoTrials, AnyChangeOfTheKeyedFilesTracksAgain) {
  const fs::path folder = CopyExperiment("content-key");
  ASSERT_TRUE(RestTrial(folder).first.error.empty());
  ASSERT_TRUE(RestTrial(folder).second);  // unchanged: from the cache
  // One byte in the middle of the video, size and mtime kept.
  const fs::path video = folder / "videos" / "rest.mp4";
  struct stat before {};
  ASSERT_EQ(::stat(video.c_str(), &before), 0);
  std::string bytes = ReadBytes(video);
  bytes[bytes.size() / 2] ^= 0x01;
  std::ofstream(video, std::ios::binary | std::ios::trunc) << bytes;
  const timespec times[2] = {before.st_atim, before.st_mtim};
  ASSERT_EQ(::utimensat(AT_FDCWD, video.c_str(), times, 0), 0);
  struct stat after {};
  ASSERT_EQ(::stat(video.c_str(), &after), 0);
  ASSERT_EQ(after.st_size, before.st_size);
  ASSERT_EQ(MtimeNs(video), before.st_mtim.tv_sec * 1000000000L + before.st_mtim.tv_nsec);
  EXPECT_FALSE(RestTrial(folder).second) << "a changed video was served from the cache";
  ASSERT_TRUE(RestTrial(folder).second);
  for (const char* file : {"calibration/camera.json", "calibration/scene-main.json"}) {
    std::ofstream(folder / file, std::ios::app) << "\n";  // the same calibration, other bytes
    EXPECT_FALSE(RestTrial(folder).second) << file << " changed, yet served from the cache";
    ASSERT_TRUE(RestTrial(folder).second);
  }
  fs::remove_all(folder);
}

// The tracker's version is part of the key (a compile-time constant: the key function is asked
// with two versions). Truth: the key's definition: 32 hex digits, the video's hash first.
TEST(VideoCacheKey, TheTrackerVersionIsPartOfTheKey) {
  Configuration c;
  const VideoAnalysisSettings v;
  const std::string a = VideoCacheKey("0123456789abcdef", "camera", "scene", c, v, 15);
  EXPECT_EQ(a.size(), 32u);
  EXPECT_EQ(a.substr(0, 16), "0123456789abcdef");
  EXPECT_EQ(a, VideoCacheKey("0123456789abcdef", "camera", "scene", c, v, 15));
  EXPECT_NE(a, VideoCacheKey("0123456789abcdef", "camera", "scene", c, v, 16));
  EXPECT_NE(a, VideoCacheKey("0123456789abcdef", "camera2", "scene", c, v, 15));
  EXPECT_NE(a, VideoCacheKey("0123456789abcdef", "camera", "scene2", c, v, 15));
  EXPECT_EQ(VideoCacheKey("0123456789abcdef", "camera", "scene", c, v), VideoCacheKey("0123456789abcdef", "camera", "scene", c, v, kVideoTrackerVersion));
}

// A cached trial.json is read as input: out-of-range, non-finite or mistyped values are named.
// Truth: the ranges VideoTrialFromJson states (report/video_trials.hpp).
TEST(VideoTrialsReport, ACachedTrialIsCheckedAsInput) {
  VideoTrial t;
  t.trial = "a";
  t.row = 2;
  t.video = "v.mp4";
  t.frames = 10;
  t.found = 9;
  t.rest = Estimate{0.3, 0.001};
  const nlohmann::json good = VideoTrialToJson(t);
  EXPECT_EQ(VideoTrialFromJson(good).rest->value, 0.3);
  const auto refused = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& key) {
    nlohmann::json j = good;
    edit(j);
    try {
      VideoTrialFromJson(j);
      ADD_FAILURE() << j.dump() << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.quantity(), key) << e.what();
    }
  };
  refused([](auto& j) { j["rest_x"]["value"] = 1e308; }, "rest_x.value");
  refused([](auto& j) { j["rest_x"]["u"] = -1.0; }, "rest_x.u");
  refused([](auto& j) { j["found"] = 11; }, "found");
  refused([](auto& j) { j["frames"] = 1e308; }, "frames");
  refused([](auto& j) { j["fitted"] = "x"; }, "fitted");
  refused([](auto& j) { j.erase("notes"); }, "notes");
  refused([](auto& j) { j["figure"]["measured"] = {{0.0, 1e300}}; }, "figure.measured");
}

// Guards: POST /api/report of `uphill serve` wrote the report into EXP/report/ over an input named
// there ("camera": "report/fit.json"). The handler and `uphill report` share CheckReportOutputs.
// Truth: the rule (no output is an input), and the message naming both.
TEST(ReportOutputs, ThePagesReportFolderNeverReplacesAnInput) {
  const fs::path folder = FreshFolder("page-report-inputs");
  fs::create_directories(folder / "report");
  std::ofstream(folder / "experiment.json") << R"({"format": "uphill-experiment/2",
    "body": {"type": "sphere", "R": "25.4 mm"}, "apparatus": {"L": "1000 mm", "H": "100 mm"},
    "camera": "report/fit.json", "scenes": {"main": "report/report.md"}})";
  std::ofstream(folder / "measurements.csv") << "trial,D_mm,Y_mm,video\na,150,340,report/fit_offset.png\n";
  const auto refused = [&](const std::string& input, const std::string& what) {
    std::ofstream(folder / input) << "input\n";
    try {
      CheckReportOutputs(LoadExperiment(folder.string()), (folder / "report").string(), "report");
      ADD_FAILURE() << input << " was not named";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find((folder / input).string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
    fs::remove(folder / input);
  };
  refused("report/fit.json", "camera file");
  refused("report/report.md", "scene file 'main'");
  refused("report/fit_offset.png", "video of trial 'a'");
  EXPECT_NO_THROW(CheckReportOutputs(LoadExperiment(folder.string()), (folder / "report").string(), "report"));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace uphill::testing
