// Video trials: each trial's recording of an experiment folder (format uphill-experiment/2,
// data/README.md) tracked (vision/video_tracking.hpp) and analysed (vision/track_analysis.hpp)
// with the experiment's camera, the row's scene, and the row's body and apparatus values; then
// the fit report of the experiment with what the videos measured (report/video_trials.hpp).
// Used by `uphill report` / `uphill fit` (through uphill-vision: tools/uphill/vision_program.hpp),
// the page of `uphill serve` and the tests.
//
// Cache: EXP/.uphill-cache/video/<key>/ holds track.csv, track.csv.json (vision's track files),
// track_analysis.json (analyse-track's) and trial.json (the VideoTrial the report reads), written
// into a staging folder and renamed into place whole. <key> = XXH3-64 of the video's bytes (16 hex
// digits) + XXH3-64 of the camera and scene files' bytes, the row's body and apparatus values, the
// analysis options and kVideoTrackerVersion (16 hex digits). A hit reads trial.json only (and
// hashes the video: XXH3 runs at memory speed, so 20 videos of 1080p, 10 s take well under 1 s
// from the page cache). A cache entry is input: its trial.json is checked as any input is
// (report/video_trials.hpp: keys, types, finite numbers in range); a damaged one is tracked again
// and replaced, and VideoTrial::cache_note says so in one line.
// Several runs may fill the same entry at once (parallel `uphill fit`): the first rename wins and
// the others take its entry (checked the same way) and drop their own.
// A folder whose cache cannot be written (read-only, a file or a link at .uphill-cache) keeps its
// entries readable; new ones go into the user's cache, $XDG_CACHE_HOME/uphill/video (else
// $HOME/.cache/uphill/video), or, when that cannot be written either, nowhere (tracked each run).
//
// Files: the camera, scene and video paths are relative to the folder and opened through
// io/contained_directory.hpp: a symbolic link at any level is refused, as is anything that is not
// a regular file.
//
// The trial's Y from its video: the analysis' final rest x_r, with u(Y) = sqrt(se(x_r)² + u_x²)
// (u_x: video_analysis.u_x, the stated uncertainty of one tracked position; the frames of a rest
// share the calibration's and the tracker's systematic error, which averaging does not reduce).
//
// Bad input of one trial (a missing file or link, a file that is not a video, a scene whose image
// size is not the video's, a body that is never found, a double cone) is that trial's error: a
// one-line message naming the trial and the file; the other trials are still analysed.
// Threads: TrackExperimentVideos runs `jobs` trials at once, one per thread, each decoding on
// one thread (OneDecodeThreadPerVideo), so that the cores are used across videos, largest first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "io/experiment.hpp"
#include "report/analysis.hpp"
#include "report/video_trials.hpp"
#include "vision/track_table.hpp"

namespace uphill {

// Changes to the tracker or the analysis that change their results bump this: old cache entries
// are then not used.
inline constexpr int kVideoTrackerVersion = 49;

// What a progress callback is told. Calls are serialised (never two at once), from the threads
// that do the work.
struct VideoProgress {
  enum class Stage { kQueued, kHashing, kTracking, kAnalysing, kCached, kDone, kFailed };
  std::size_t index = 0;  // into the list of video rows
  std::string trial;
  Stage stage = Stage::kQueued;
  int frames_done = 0;
  long frames_total = 0;  // the container's declared count (0: unknown)
};
using VideoProgressCallback = std::function<void(const VideoProgress&)>;

// One trial's video: from the cache, or tracked and analysed and then cached. Never throws for
// bad input of the trial: VideoTrial::error says what (naming the trial and the file); throws
// EnvironmentError only when the cache cannot be written.
VideoTrial TrackTrialVideo(const Experiment& experiment, const ExperimentRow& row, std::size_t index = 0,
                           const VideoProgressCallback& progress = {});

// For the page: the trial of data row `row_index` (0-based, file order) of the folder's
// measurements.csv, loaded as LoadExperiment reads it, with its track (the frames of track.csv as
// the cache keeps them, SI; empty on error). Throws what LoadExperiment throws, and InputError
// when the row has no video or is out of range.
struct VideoTrialResult {
  VideoTrial trial;
  Track track;
};
VideoTrialResult TrackTrialVideo(const std::string& folder, std::size_t row_index,
                                 const VideoProgressCallback& progress = {});

// Called with a trial as soon as it is finished (tracked, from the cache, or failed) and its index
// into VideoRows; serialised with the progress calls. The report draws the trial's figures then,
// while the other videos are still being tracked.
using VideoTrialDoneCallback = std::function<void(std::size_t index, const VideoTrial& trial)>;

// Every row with a video, `jobs` at a time (0: std::thread::hardware_concurrency()); the result is
// in row order. The largest files are started first: the file size stands for the decoding work
// (the frames, their size, and the bits per frame), so that no long video is left to run alone on
// one core at the end while the others are idle.
std::vector<VideoTrial> TrackExperimentVideos(const Experiment& experiment, unsigned jobs = 0,
                                              const VideoProgressCallback& progress = {},
                                              const VideoTrialDoneCallback& done = {});

// The rows with a video, in file order (what the callbacks' index refers to).
std::vector<const ExperimentRow*> VideoRows(const Experiment& experiment);

// The experiment with the videos' rest positions filled in as Y where Y was empty (a row whose
// video gave no rest gets that as its error), then its analysis (report/analysis.hpp) carrying
// the trials. `experiment` is changed (the analysis points into it).
ExperimentAnalysis AnalyseExperimentWithVideos(Experiment* experiment, const std::vector<VideoTrial>& trials,
                                               const AnalysisOptions& options = {});

// Sets FFmpeg (through OpenCV) and OpenCV to one thread per video: call before any video is
// opened, when several videos are decoded at once. Process-wide (environment variables).
void OneDecodeThreadPerVideo();

// XXH3-64 of a file's bytes as 16 lower-case hex digits. Throws EnvironmentError naming the file.
std::string HashFileContent(const std::string& path);

// A trial's cache key: `video_hash` (HashFileContent of the video), then 16 hex digits of XXH3-64
// over the camera and scene files' bytes, the row's body and apparatus values, the analysis
// options and `tracker_version`. Any change of these is another key, so the trial is tracked again.
std::string VideoCacheKey(const std::string& video_hash, const std::string& camera_bytes,
                          const std::string& scene_bytes, const Configuration& configuration,
                          const VideoAnalysisSettings& analysis, int tracker_version = kVideoTrackerVersion);

}  // namespace uphill
