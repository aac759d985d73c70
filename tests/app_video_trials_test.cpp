// The video trials of an experiment folder (app/video_trials.hpp): tracked, analysed, cached, and
// carried into the fit report. Truth: tools/make_video's renderer (synthetic_clip.hpp), whose
// ground truth is exact: the body's true rest position (truth CSV) and the μ the clip's motion was
// made with. Clips are small (640 × 360, ~1–2 s) to keep the suite fast.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <cmath>
#include <sstream>

#include "app/video_trials.hpp"
#include "file_test_support.hpp"
#include "io/experiment.hpp"
#include "report/fit_document.hpp"
#include "report/fit_json.hpp"

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
  EXPECT_NE(text.find("mu from the motions: "), std::string::npos);
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
  trials[0].fit_value = MeasuredValue{0.04, 0.01};
  trials[1].fit_value = MeasuredValue{0.06, 0.02};
  trials[2].fit_value = MeasuredValue{0.5, 0.01};
  trials[2].error = "failed";  // left out
  const auto m = WeightedMotionMu(trials);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->trials, 2);
  EXPECT_NEAR(m->mu, 0.044, 1e-15);
  EXPECT_NEAR(m->u, 1.0 / std::sqrt(12500.0), 1e-15);
  // χ² = (0.004/0.01)² + (0.016/0.02)² = 0.16 + 0.64, ν = 1.
  EXPECT_NEAR(*m->reduced_chi2, 0.8, 1e-12);
}

}  // namespace
}  // namespace uphill::testing
