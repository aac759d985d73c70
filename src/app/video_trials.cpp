#include "app/video_trials.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>

#include "app/track_analysis_output.hpp"
#include "app/track_video_file.hpp"
#include "io/atomic_file.hpp"
#include "io/contained_directory.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"
#include "vision/track_analysis.hpp"
#include "vision/track_table.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kCacheFolder = std::string(kVideoCacheFolder) + "/video";
constexpr const char* kTrialFile = "trial.json";
constexpr std::size_t kMaxCalibrationBytes = 16u << 20;

std::string Hex16(std::uint64_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

TrackAnalysisOptions AnalysisOptionsOf(const VideoAnalysisSettings& v) {
  TrackAnalysisOptions o;
  o.g = v.g;
  o.u_x = v.u_x;
  o.fit = v.fit == "mu" ? TrackFitParameter::kMu : TrackFitParameter::kEffectiveG;
  return o;
}

// The uncertainty analyse-track says to quote (track_analysis.hpp, "Uncertainty of the fit"):
// u carries the tracker's systematic error, which the scatter of the residuals does not show
// (se_scaled shrinks below the real error when chi2/dof < 1).
Estimate Quoted(const FittedParameter& p) {
  return {p.value, p.u ? p.u : p.se_scaled ? p.se_scaled : p.se};
}

// The report's plain numbers of an analysis.
void FillFromAnalysis(const TrackAnalysis& a, VideoTrial* t) {
  t->frames = a.frames;
  t->found = a.found;
  if (a.release) {
    t->release_x = a.release->x;
    t->release_t = a.release->t;
    t->events.push_back(*a.release);
  }
  t->events.insert(t->events.end(), a.turning_points.begin(), a.turning_points.end());
  if (a.rest) {
    // u(Y) = sqrt(se² + u_x²): the rest's standard error from the frames' scatter, and the stated
    // uncertainty of a tracked position, which averaging over frames does not reduce (they share
    // the calibration's and the tracker's systematic error).
    t->rest = a.rest->x;
    t->rest->u = std::hypot(a.rest->x.u.value_or(0.0), a.options.u_x);
    t->events.push_back(*a.rest);
  } else {
    t->no_rest = a.fall_off    ? "never at rest: falls off the rails"
                 : a.reaches_o ? "never at rest: rolls back to O"
                               : "never at rest in the recording";
  }
  if (a.fall_off) t->events.push_back(*a.fall_off);
  if (a.reaches_o) t->events.push_back(*a.reaches_o);
  t->fit_available = a.fit.available;
  t->fit_unavailable = a.fit.unavailable;
  t->fitted = a.fit.fitted;
  if (a.fit.available) {
    if (const FittedParameter* p = a.fit.Parameter(a.fit.fitted)) {
      t->fit_value = Quoted(*p);
    }
    // The fit's own x0 and t0 are better than the band's (track_analysis.hpp: release).
    if (const FittedParameter* x0 = a.fit.Parameter("x0")) t->release_x = Quoted(*x0);
    if (const FittedParameter* t0 = a.fit.Parameter("t0")) t->release_t = Quoted(*t0);
  }
  t->reduced_chi2 = a.fit.reduced_chi2;
  t->dof = a.fit.dof;
  t->notes = a.notes;
  for (const std::string& n : a.fit.notes) t->notes.push_back(n);
  t->figure = TrackFigureDataOf(a);
}

// The folders a trial is looked up in, in order, and the one a new entry is written into.
struct CacheFolders {
  std::vector<ContainedDirectory> lookup;
  std::optional<std::size_t> write;  // into lookup; none: results are not cached
};

bool Writable(const ContainedDirectory& d) { return ::faccessat(d.fd(), ".", W_OK | X_OK, AT_EACCESS) == 0; }

// The user's cache for folders that cannot hold their own: $XDG_CACHE_HOME/uphill/video (an
// absolute path), else $HOME/.cache/uphill/video; nullopt when neither can be made.
std::optional<ContainedDirectory> UserCache() {
  std::vector<fs::path> bases;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && fs::path(xdg).is_absolute()) bases.emplace_back(xdg);
  if (const char* home = std::getenv("HOME"); home && fs::path(home).is_absolute()) bases.push_back(fs::path(home) / ".cache");
  for (const fs::path& base : bases) {
    try {
      std::error_code ignored;
      fs::create_directories(base / "uphill" / "video", ignored);
      ContainedDirectory d = ContainedDirectory::Open((base / "uphill" / "video").string());
      if (Writable(d)) return d;
    } catch (const EnvironmentError&) {
    }
  }
  return std::nullopt;
}

// EXP/.uphill-cache/video, created when needed. When it cannot be written (a read-only folder, a
// file or a link in the way) its entries are still read, and new ones go into the user's cache,
// or nowhere: a trial is then tracked on every run.
CacheFolders OpenCacheFolders(const ContainedDirectory& root) {
  CacheFolders c;
  try {
    c.lookup.push_back(root.Subdirectory(kCacheFolder, true));
    if (Writable(c.lookup.back())) c.write = 0;
  } catch (const EnvironmentError&) {
    try {
      c.lookup.push_back(root.Subdirectory(kCacheFolder, false));
    } catch (const EnvironmentError&) {
    }
  }
  if (!c.write)
    if (std::optional<ContainedDirectory> user = UserCache()) {
      c.lookup.push_back(std::move(*user));
      c.write = c.lookup.size() - 1;
    }
  return c;
}

// A cache entry read as input: its trial.json checked as any input is (report/video_trials.hpp).
struct CachedEntry {
  std::optional<VideoTrial> trial;  // absent or damaged: nullopt
  std::string damage;               // why a present entry was not used ("" absent)
};

CachedEntry ReadCached(const ContainedDirectory& cache, const std::string& key) {
  CachedEntry entry;
  try {
    const auto text = cache.ReadFile(key + "/" + kTrialFile, 64u << 20);
    if (!text) {
      if (cache.KindOf(key) != ContainedDirectory::Kind::kAbsent) entry.damage = std::string(kTrialFile) + " is missing";
      return entry;
    }
    VideoTrial t = VideoTrialFromJson(json::parse(*text));
    t.from_cache = true;
    entry.trial = std::move(t);
  } catch (const std::exception& e) {
    entry.damage = e.what();
  }
  return entry;
}

// Renames the entry written into `staging` into place as `key`. Another run may have made the
// entry meanwhile (the rename finds it there): a sound one is theirs to keep, returned, and ours
// is left for the caller to remove; a damaged one is replaced. nullopt: ours is in place.
std::optional<VideoTrial> CommitCache(const ContainedDirectory& cache, const ContainedDirectory& staging,
                                      const std::string& key) {
  const std::string staging_name = fs::path(staging.path()).filename().string();
  staging.Sync();
  for (int attempt = 0;; ++attempt) {
    try {
      cache.RenameNoReplace(staging_name, key);
      return std::nullopt;
    } catch (const EnvironmentError&) {
      if (attempt > 0 || cache.KindOf(key) == ContainedDirectory::Kind::kAbsent) throw;
    }
    if (CachedEntry theirs = ReadCached(cache, key); theirs.trial) return theirs.trial;
    ContainedDirectory::RemoveStaging(cache, cache.Subdirectory(key, false));  // damaged: replaced
  }
}

VideoTrial Failed(VideoTrial t, const std::string& message) {
  t.error = "trial '" + t.trial + "' (" + t.video + "): " + message;
  return t;
}

}  // namespace

std::string VideoCacheKey(const std::string& video_hash, const std::string& camera_bytes, const std::string& scene_bytes,
                          const Configuration& c, const VideoAnalysisSettings& v, int tracker_version) {
  // The second half: everything besides the video that decides the results.
  std::string text = "uphill-video-trial/" + std::to_string(tracker_version) + "\n";
  text += std::to_string(camera_bytes.size()) + "\n" + camera_bytes + "\n";
  text += std::to_string(scene_bytes.size()) + "\n" + scene_bytes + "\n";
  const auto value = [&](const char* name, const Uncertain& u) { text += std::string(name) + " " + Printf("%.17g", u.value) + "\n"; };
  text += "body " + std::to_string(static_cast<int>(c.body_kind)) + "\n";
  value("across", c.across);
  value("along", c.along);
  text += c.from_apparatus ? "apparatus\n" : "angles\n";
  value("L", c.L);
  value("H", c.H);
  value("D", c.D);
  text += "convention " + std::to_string(static_cast<int>(c.convention)) + "\n";
  value("theta", c.theta);
  value("alpha", c.alpha);
  value("rod_radius", c.rod_radius);
  text += "fit " + v.fit + "\nu_x " + Printf("%.17g", v.u_x) + "\ng " + Printf("%.17g", v.g) + "\n";
  return video_hash + Hex16(XXH3_64bits(text.data(), text.size()));
}

std::string HashFileContent(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw EnvironmentError(path + ": cannot open: " + std::strerror(errno));
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  std::vector<char> buffer(1u << 20);
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int saved = errno;
      ::close(fd);
      XXH3_freeState(state);
      throw EnvironmentError(path + ": cannot read: " + std::strerror(saved));
    }
    if (n == 0) break;
    XXH3_64bits_update(state, buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  const std::uint64_t h = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  return Hex16(h);
}

void OneDecodeThreadPerVideo() {
  ::setenv("OPENCV_FFMPEG_CAPTURE_OPTIONS", "threads;1", 0);
  cv::setNumThreads(1);
}

std::vector<const ExperimentRow*> VideoRows(const Experiment& experiment) {
  std::vector<const ExperimentRow*> out;
  for (const ExperimentRow& r : experiment.rows)
    if (!r.video.empty() && r.error.empty()) out.push_back(&r);
  return out;
}

namespace {

// The trial, tracked or from a cache entry; `track_out`, when given, receives its track.
VideoTrial TrackTrial(const Experiment& experiment, const ExperimentRow& row, std::size_t index,
                      const VideoProgressCallback& progress, Track* track_out) {
  VideoTrial trial;
  trial.trial = row.trial;
  trial.row = row.row;
  trial.video = row.video;
  VideoProgress p;
  p.index = index;
  p.trial = row.trial;
  const auto tell = [&](VideoProgress::Stage stage) {
    p.stage = stage;
    if (progress) progress(p);
  };
  // The trial as a cache entry holds it, with this row's labels.
  const auto served = [&](VideoTrial cached, const ContainedDirectory& cache, const std::string& key) {
    cached.trial = row.trial;
    cached.row = row.row;
    cached.video = row.video;
    cached.cache_note = trial.cache_note;
    if (track_out) *track_out = ReadTrackFile((fs::path(cache.path()) / key / "track.csv").string());
    return cached;
  };
  try {
    if (!row.configuration) throw InputError("row " + std::to_string(row.row), "has no usable apparatus values");
    const Scene scene = row.configuration->MakeScene();
    if (scene.body().kind == BodyKind::kDoubleCone) throw InputError("body", kDoubleConeRefusal);  // before any file is read
    const ContainedDirectory root = ContainedDirectory::Open(experiment.directory);
    const std::string scene_file = experiment.scenes.at(row.scene);
    const auto camera_bytes = root.ReadFile(experiment.camera, kMaxCalibrationBytes);
    if (!camera_bytes) throw InputError(experiment.camera, "the camera file is missing");
    const auto scene_bytes = root.ReadFile(scene_file, kMaxCalibrationBytes);
    if (!scene_bytes) throw InputError(scene_file, "the scene file '" + row.scene + "' is missing");
    const ContainedDirectory::Kind kind = root.KindOf(row.video);
    if (kind == ContainedDirectory::Kind::kAbsent) throw InputError(row.video, "no such file");
    if (kind != ContainedDirectory::Kind::kFile)
      throw InputError(row.video, "is not a regular file in the folder (links are not followed)");
    const std::string video_path = (fs::path(root.path()) / row.video).string();
    tell(VideoProgress::Stage::kHashing);
    const std::string key = VideoCacheKey(HashFileContent(video_path), *camera_bytes, *scene_bytes,
                                          *row.configuration, experiment.video_analysis);
    const CacheFolders caches = OpenCacheFolders(root);
    for (const ContainedDirectory& cache : caches.lookup) {
      CachedEntry entry = ReadCached(cache, key);
      if (entry.trial) {
        tell(VideoProgress::Stage::kCached);
        return served(std::move(*entry.trial), cache, key);
      }
      if (!entry.damage.empty())
        trial.cache_note = "trial '" + row.trial + "' (" + row.video + "): the cached result " + (fs::path(cache.path()) / key).string() + " is damaged (" +
                           entry.damage + "): tracked again";
    }
    const std::string camera_path = (fs::path(root.path()) / experiment.camera).string();
    const std::string scene_path = (fs::path(root.path()) / scene_file).string();
    TrackVideoFileOptions options;
    options.video_label = row.video;
    options.scene_label = scene_file;
    const FrameProgressCallback frames = [&](int done, long total) {
      p.frames_done = done;
      p.frames_total = total;
      tell(VideoProgress::Stage::kTracking);
    };
    tell(VideoProgress::Stage::kTracking);
    const TrackResult track = TrackVideoFile(video_path, camera_path, scene_path, scene, options, frames);
    trial.partial = track.partial;
    trial.partial_reason = track.partial_reason;
    trial.tracker_cpu_seconds = track.tracker_cpu_seconds;
    tell(VideoProgress::Stage::kAnalysing);
    // The entry is written into a staging folder and renamed into place whole (without a
    // writable cache, a private temporary folder, removed after). The analysis reads the track as
    // the cache keeps it (the CSV's millimetres), so that a fresh run and a cached one agree: the
    // track is written first, once, and read back.
    const TrackSources sources{row.video, experiment.camera, scene_file, scene.body().Name()};
    std::optional<ContainedDirectory> temporary;
    if (!caches.write) temporary = ContainedDirectory::Open(fs::temp_directory_path().string());
    const ContainedDirectory& parent = caches.write ? caches.lookup[*caches.write] : *temporary;
    ContainedDirectory staging = parent.MakeStagingDirectory(caches.write ? ".staging-" : "uphill-track-");
    std::optional<VideoTrial> theirs;
    try {
      const std::string csv = (fs::path(staging.path()) / "track.csv").string();
      WriteTrack(csv, track, sources);
      Track read = ReadTrackFile(csv);
      read.source = row.video;
      const TrackAnalysis analysis = AnalyseTrack(read, scene, AnalysisOptionsOf(experiment.video_analysis));
      FillFromAnalysis(analysis, &trial);
      if (track_out) *track_out = std::move(read);
      staging.WriteFileAtomically("track_analysis.json", TrackAnalysisJson(analysis).dump(2) + "\n");
      staging.WriteFileAtomically(kTrialFile, VideoTrialToJson(trial).dump() + "\n");
      if (caches.write) theirs = CommitCache(parent, staging, key);
    } catch (...) {
      ContainedDirectory::RemoveStaging(parent, std::move(staging));
      throw;
    }
    if (!caches.write || theirs) ContainedDirectory::RemoveStaging(parent, std::move(staging));
    if (caches.write) parent.Sync();
    if (theirs) {  // another run made the entry meanwhile: the results are theirs
      tell(VideoProgress::Stage::kCached);
      return served(std::move(*theirs), parent, key);
    }
    tell(VideoProgress::Stage::kDone);
    return trial;
  } catch (const InputError& e) {
    tell(VideoProgress::Stage::kFailed);
    return Failed(trial, e.what());
  } catch (const EnvironmentError& e) {
    tell(VideoProgress::Stage::kFailed);
    return Failed(trial, e.what());
  }
}

}  // namespace

VideoTrial TrackTrialVideo(const Experiment& experiment, const ExperimentRow& row, std::size_t index,
                           const VideoProgressCallback& progress) {
  return TrackTrial(experiment, row, index, progress, nullptr);
}

VideoTrialResult TrackTrialVideo(const std::string& folder, std::size_t row_index,
                                 const VideoProgressCallback& progress) {
  const Experiment experiment = LoadExperiment(folder);
  if (row_index >= experiment.rows.size())
    throw InputError(folder + "/measurements.csv", "has no data row " + std::to_string(row_index + 2));
  const ExperimentRow& row = experiment.rows[row_index];
  if (!row.error.empty()) {
    const std::size_t colon = row.error.find(": ");
    throw InputError(row.error.substr(0, colon), colon == std::string::npos ? "is not usable" : row.error.substr(colon + 2));
  }
  if (row.video.empty()) throw InputError(folder + "/measurements.csv, row " + std::to_string(row.row) + ", column video", "is empty");
  VideoTrialResult result;
  result.trial = TrackTrial(experiment, row, 0, progress, &result.track);
  return result;
}

namespace {

// The rows in the order they are started: the largest file first (the file size stands for the
// decoding work); a file that cannot be sized fails (quickly) when it is opened, last.
std::vector<std::size_t> LongestFirst(const Experiment& experiment, const std::vector<const ExperimentRow*>& rows) {
  std::vector<std::uintmax_t> bytes(rows.size(), 0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::error_code ignored;
    const std::uintmax_t size = fs::file_size(fs::path(experiment.directory) / rows[i]->video, ignored);
    bytes[i] = ignored ? 0 : size;
  }
  std::vector<std::size_t> order(rows.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return bytes[a] > bytes[b]; });
  return order;
}

}  // namespace

std::vector<VideoTrial> TrackExperimentVideos(const Experiment& experiment, unsigned jobs,
                                              const VideoProgressCallback& progress,
                                              const VideoTrialDoneCallback& done) {
  const std::vector<const ExperimentRow*> rows = VideoRows(experiment);
  std::vector<VideoTrial> out(rows.size());
  if (rows.empty()) return out;
  if (jobs == 0) jobs = std::max(1u, std::thread::hardware_concurrency());
  jobs = std::min<unsigned>(jobs, static_cast<unsigned>(rows.size()));
  std::mutex callback_mutex;
  const VideoProgressCallback serialised = [&](const VideoProgress& p) {
    if (!progress) return;
    std::lock_guard<std::mutex> lock(callback_mutex);
    progress(p);
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    VideoProgress queued;
    queued.index = i;
    queued.trial = rows[i]->trial;
    serialised(queued);
  }
  const std::vector<std::size_t> order = LongestFirst(experiment, rows);
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    for (std::size_t k = next++; k < order.size(); k = next++) {
      const std::size_t i = order[k];
      try {
        out[i] = TrackTrialVideo(experiment, *rows[i], i, serialised);
        if (done) {
          std::lock_guard<std::mutex> lock(callback_mutex);
          done(i, out[i]);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (unsigned j = 1; j < jobs; ++j) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
  return out;
}

ExperimentAnalysis AnalyseExperimentWithVideos(Experiment* experiment, const std::vector<VideoTrial>& trials,
                                               const AnalysisOptions& options) {
  for (const VideoTrial& t : trials) {
    for (ExperimentRow& row : experiment->rows) {
      if (row.row != t.row || !row.error.empty() || row.y_typed) continue;
      if (!t.error.empty()) {
        // The video's own error is reported once, with the videos; the row says only why it
        // has no Y.
        row.error = "trial '" + t.trial + "' (" + t.video + "): Y is empty and its video could not be analysed (above)";
      } else if (!t.rest) {
        row.error = "trial '" + t.trial + "' (" + t.video + "): Y is empty and the video gives none: " + t.no_rest;
      } else {
        row.Y.value = t.rest->value;
        row.Y.u = t.rest->u.value_or(0.0);
      }
    }
  }
  ExperimentAnalysis analysis = AnalyseExperiment(*experiment, options);
  analysis.video_trials = trials;
  return analysis;
}

}  // namespace uphill
