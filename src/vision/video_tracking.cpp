#include "vision/video_tracking.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/output_paths.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "internal/doubtful_rows.hpp"
#include "internal/track_series.hpp"
#include "vision/library_logs.hpp"
#include "vision/track_analysis.hpp"

namespace uphill {
namespace {

// A single position's error beyond the tracker's systematic part (the edge bias that neighbouring
// frames share, TrackAnalysisOptions' model): px on each image axis. On 5 seeds of random
// ray-traced scenes (196 scenes, 6226 frames within a pixel of the truth) the truth lay within
// 2.45 hypot(systematic, this) in 94.6 % of the frames, where the systematic part alone held 86 %:
// much of the rest is a steady bias of a few tenths of a pixel on one axis of a scene, which the
// frames' own scatter does not show.
constexpr double kPositionScatterPx = 0.10;

// TrackRow::u_px and u_x of every row where the ball was found.
void AddUncertainties(double body_across, std::vector<TrackRow>* rows) {
  std::vector<double> t, u, v;
  std::vector<TrackRow*> found;
  for (TrackRow& r : *rows)
    if (r.ball.found) t.push_back(r.t), u.push_back(r.ball.u), v.push_back(r.ball.v), found.push_back(&r);
  const std::vector<double> speed = internal::PixelsPerFrame(t, u, v);
  const TrackAnalysisOptions error_model;
  for (std::size_t i = 0; i < found.size(); ++i) {
    TrackRow& r = *found[i];
    const double systematic = std::max(error_model.tracker_floor_px + error_model.tracker_blur * speed[i],
                                       r.ball.outline_spread_px);
    r.u_px = std::hypot(systematic, kPositionScatterPx);
    r.u_x = r.ball.radius_px > 0 ? r.u_px * body_across / r.ball.radius_px : 0.0;
  }
}

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string Size(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// A file written by a library that takes a path (OpenCV's VideoWriter): it writes under a
// temporary name in the target's folder (same extension: it picks the container), and the file
// is renamed into place only by Commit, so a failed or interrupted run never leaves a half-written
// file at the target's name nor touches what is there. The temporary is removed otherwise.
class PendingFile {
 public:
  explicit PendingFile(const std::string& target) : target_(target) {
    const std::filesystem::path path(target);
    folder_ = path.has_parent_path() ? path.parent_path().string() : ".";
    OutputPaths::CreateFolders(folder_);
    unsigned long long r = 0;
    if (::getrandom(&r, sizeof r, 0) != static_cast<ssize_t>(sizeof r)) r = static_cast<unsigned long long>(::getpid());
    char suffix[24];
    std::snprintf(suffix, sizeof suffix, ".tmp-%016llx", r);
    name_ = "." + path.stem().string() + suffix + path.extension().string();
    temporary_ = (std::filesystem::path(folder_) / name_).string();
  }
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;
  ~PendingFile() {
    if (!committed_) ::unlink(temporary_.c_str());
  }
  const std::string& temporary() const { return temporary_; }
  // fsync, then rename over the target (never over anything but a regular file).
  void Commit() {
    const int fd = ::open(temporary_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
      if (fd >= 0) ::close(fd);
      throw EnvironmentError(target_ + ": cannot be saved: " + std::strerror(errno));
    }
    ::close(fd);
    const int dir = ::open(folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0) throw EnvironmentError(folder_ + ": cannot open the folder: " + std::strerror(errno));
    try {
      RenameIntoPlaceAt(dir, name_, dir, folder_, std::filesystem::path(target_).filename().string());
    } catch (...) {
      ::close(dir);
      throw;
    }
    ::close(dir);
    committed_ = true;
  }

 private:
  std::string target_, folder_, name_, temporary_;
  bool committed_ = false;
};

// The scene's centre path and the fitted outline and centre, drawn on a copy of the frame.
void DrawOverlay(cv::Mat& frame, const BallTracker& tracker, const std::vector<cv::Point>& path, const BallObservation& b) {
  cv::polylines(frame, path, false, cv::Scalar(255, 200, 0), 1, cv::LINE_AA, 4);
  if (!b.found) {
    cv::putText(frame, "ball not found", cv::Point(20, 40), cv::FONT_HERSHEY_SIMPLEX, 1.0, cv::Scalar(0, 0, 255), 2);
    return;
  }
  std::vector<cv::Point> outline;
  for (const Eigen::Vector2d& p : tracker.Outline(b.x, b.z, 72))
    outline.emplace_back(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16)));
  cv::polylines(frame, outline, true, cv::Scalar(0, 255, 0), 1, cv::LINE_AA, 4);
  cv::drawMarker(frame, cv::Point(static_cast<int>(std::lround(b.u)), static_cast<int>(std::lround(b.v))),
                 cv::Scalar(0, 255, 255), cv::MARKER_CROSS, 10, 1);
  char text[96];
  std::snprintf(text, sizeof text, "x = %.1f mm  z = %.1f mm  q = %.2f", b.x * 1e3, b.z * 1e3, b.quality);
  cv::putText(frame, text, cv::Point(20, 40), cv::FONT_HERSHEY_SIMPLEX, 0.8, cv::Scalar(0, 255, 0), 2);
}

// A frame measured again (BallTracker::TakeRevisions): its row takes the new observation, the
// time offset moving with it.
void Revise(std::vector<TrackRow>& rows, long frame, const BallObservation& revised) {
  if (frame < 0 || frame >= static_cast<long>(rows.size())) return;
  TrackRow& row = rows[frame];
  row.t += revised.time_offset - row.ball.time_offset;
  row.ball = revised;
}

}  // namespace

TrackResult TrackVideo(const std::string& video_path, const Scene& scene, const SceneCalibration& calibration,
                       const TrackVideoOptions& options) {
  if (!std::filesystem::is_regular_file(video_path)) throw InputError(video_path, "no such video file");
  QuietVideoLibraryLogs();
  cv::VideoCapture capture;
  try {
    capture.open(video_path, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
  }
  if (!capture.isOpened()) throw InputError(video_path, "is not a video that OpenCV/FFmpeg can read");
  TrackResult result;
  result.fps = capture.get(cv::CAP_PROP_FPS);
  result.image_height = calibration.camera.height;
  const double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
  result.declared_frames = count > 0 && std::isfinite(count) ? static_cast<long>(std::llround(count)) : 0;
  const int width = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_WIDTH));
  const int height = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_HEIGHT));
  if (width != calibration.camera.width || height != calibration.camera.height)
    throw InputError(options.calibration_name, "is for " + Size(calibration.camera.width, calibration.camera.height) +
                                                   " px images but " + video_path + " has " + Size(width, height) +
                                                   " px frames (calibrate the camera at the video's resolution)");
  TrackerOptions tracker_options = options.tracker;
  if (result.fps > 0 && std::isfinite(result.fps)) tracker_options.fps = result.fps;
  // The tracker's own time: its set-up, every frame and the work at the end of the clip.
  const double setup_cpu0 = ThreadCpuSeconds();
  BallTracker tracker(scene, calibration, tracker_options);
  result.tracker_cpu_seconds += ThreadCpuSeconds() - setup_cpu0;

  std::optional<PendingFile> overlay_file;  // destroyed after the writer: it closes first
  std::optional<cv::VideoWriter> overlay;
  std::vector<cv::Point> path;
  if (!options.overlay_path.empty()) {
    overlay_file.emplace(options.overlay_path);
    try {
      overlay.emplace(overlay_file->temporary(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'),
                      result.fps > 0 ? result.fps : 30.0, cv::Size(width, height));
    } catch (const cv::Exception&) {
      overlay.reset();
    }
    if (!overlay || !overlay->isOpened())
      throw EnvironmentError(options.overlay_path +
                             ": cannot write a video there (FFmpeg has no H.264 encoder for this container, or the "
                             "folder cannot be written; use a .mp4 name in a writable folder)");
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i <= 200; ++i) {
      const double x = scene.x_low() + (scene.x_max() - scene.x_low()) * i / 200.0;
      points.emplace_back(x, 0, scene.At(x).z);
    }
    for (const Eigen::Vector2d& p : ProjectApparatusPoints(calibration.camera, calibration.pose, points))
      path.emplace_back(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16)));
  }

  const double period = result.fps > 0 ? 1.0 / result.fps : 1.0 / 30.0;
  double last_frame_time = 0;  // the container's (or extrapolated) time of the previous frame
  cv::Mat frame;
  bool read_error = false;
  while (true) {
    bool ok = false;
    try {
      ok = capture.read(frame);
    } catch (const cv::Exception&) {
      read_error = true;
    }
    if (!ok || frame.empty()) break;
    TrackRow row;
    row.frame = static_cast<int>(result.rows.size());
    double t = capture.get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    // A container gives no time for some frames (FFmpeg: the last frames of an H.264 stream with
    // B-frames): one period after the previous frame's, not after its row time (a rolling
    // shutter's row delay is added below, once).
    if (!result.rows.empty() && !(t > last_frame_time)) {
      t = last_frame_time + period;
      ++result.extrapolated_times;
    }
    last_frame_time = t;
    row.t = t;
    const double cpu0 = ThreadCpuSeconds();
    row.ball = tracker.Track(frame);
    result.tracker_cpu_seconds += ThreadCpuSeconds() - cpu0;
    row.t += row.ball.time_offset;
    for (auto& [k, revised] : tracker.TakeRevisions()) Revise(result.rows, k, revised);
    if (overlay) {
      DrawOverlay(frame, tracker, path, row.ball);
      overlay->write(frame);
    }
    result.rows.push_back(row);
    if (options.progress) options.progress(static_cast<int>(result.rows.size()), result.declared_frames);
  }
  const double finish_cpu0 = ThreadCpuSeconds();
  tracker.Finish();
  result.tracker_cpu_seconds += ThreadCpuSeconds() - finish_cpu0;
  for (auto& [k, revised] : tracker.TakeRevisions()) Revise(result.rows, k, revised);
  if (result.rows.empty())
    throw InputError(video_path, "has no frame that can be decoded (not a video, or corrupt from the start)");
  result.exposure = tracker_options.exposure;
  if (const auto e = tracker.ExposureEstimate()) {
    result.measured_exposure = e->seconds;
    result.measured_exposure_frames = e->frames;
  }
  result.readout = tracker_options.readout;
  result.readout_asked = tracker_options.measure_readout;
  const auto measured = tracker.ReadoutEstimate();
  if (measured) {
    result.readout = measured->seconds;
    result.measured_readout_frames = measured->frames;
    result.readout_u = measured->u;
  } else if (tracker_options.measure_readout) {
    // A rolling shutter whose shear the clip never showed: its readout lies between 0 and the
    // frame time (a video's rows are read within one frame), so half a frame ± the spread of that
    // range (uniform: 1/(fps·√12)). Taking 0 put every time early by up to a frame; analyse-track
    // carries the uncertainty into t0 (readout_u_s).
    result.readout = 0.5 / tracker_options.fps;
    result.readout_u = 1 / (tracker_options.fps * std::sqrt(12.0));
  }
  if (result.readout > 0 && result.readout_asked) {
    // Every frame's time with the clip's readout: a frame measured before it was known, or with
    // the estimate the clip had reached, still has its centre where the body was when the
    // centre's row was exposed (the shear about that row leaves it in place).
    for (TrackRow& row : result.rows)
      if (row.ball.found) {
        const double offset = row.ball.v * result.readout / calibration.camera.height;
        row.t += offset - row.ball.time_offset;
        row.ball.time_offset = offset;
      }
  }
  result.transfer = tracker_options.transfer;
  result.frames_left_off_path = tracker.FramesLeftOffPath();
  result.frames_of_poor_fit = internal::LeaveOutDoubtfulRows(tracker_options.min_report_quality, &result.rows);
  const long read = static_cast<long>(result.rows.size());
  // A scene change (the camera moved): no position from that frame on, the calibration no longer
  // holds there.
  if (const auto changed = tracker.SceneChangedAt()) {
    for (TrackRow& r : result.rows)
      if (r.frame >= *changed) r.ball = BallObservation{};
  }
  AddUncertainties(scene.body().across, &result.rows);
  int found = 0, last_found = -1;
  for (const TrackRow& r : result.rows)
    if (r.ball.found) ++found, last_found = r.frame;
  if (read_error || (result.declared_frames > 0 && read < result.declared_frames - 1)) {
    result.partial = true;
    result.input_problem = true;
    result.partial_reason = "the video ends after " + std::to_string(read) + " of the " +
                            std::to_string(result.declared_frames) + " frames its container declares (truncated or corrupt)";
  } else if (const auto changed = tracker.SceneChangedAt()) {
    result.partial = true;
    result.input_problem = true;
    result.partial_reason = "the picture outside the body changed at frame " + std::to_string(*changed) +
                            " beyond noise and lighting (the camera moved, or the scene was disturbed): the scene "
                            "calibration no longer holds, so no positions are reported from that frame on";
  } else if (found == 0) {
    result.partial = true;
    result.input_problem = true;
    result.partial_reason = "the body was found in none of the " + std::to_string(read) +
                            " frames along the rails' path (is it in the picture? check the scene file and the body flags)";
  } else if (!tracker.ExposureChanges().empty()) {
    result.partial = true;
    result.input_problem = true;
    std::string frames;
    for (long k : tracker.ExposureChanges()) frames += (frames.empty() ? "" : ", ") + std::to_string(k);
    result.exposure_changes = tracker.ExposureChanges();
    result.partial_reason = "the exposure changed at frame " + frames +
                            " (the brightness of the whole picture jumped and stayed): the positions after it are "
                            "measured with the new exposure, but a clip for analysis should keep one exposure";
  } else if (last_found + 1 < read) {
    result.partial = true;
    result.partial_reason = "the ball was lost after frame " + std::to_string(last_found) + " and not found again in the last " +
                            std::to_string(read - last_found - 1) + " frames";
  }
  if (overlay) {
    overlay->release();
    overlay_file->Commit();
  }
  return result;
}

void WriteTrack(const std::string& csv_path, const TrackResult& result, const TrackSources& sources) {
  std::ostringstream csv;
  csv << "frame,t,u,v,radius_px,x,z,quality,u_px,u_x,u_outline_px\n";
  char line[256];
  for (const TrackRow& r : result.rows) {
    if (r.ball.found)
      std::snprintf(line, sizeof line, "%d,%.6f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", r.frame, r.t, r.ball.u,
                    r.ball.v, r.ball.radius_px, r.ball.x * 1e3, r.ball.z * 1e3, std::max(1e-4, r.ball.quality), r.u_px,
                    r.u_x * 1e3, r.ball.outline_spread_px);
    else
      std::snprintf(line, sizeof line, "%d,%.6f,,,,,,0,,,\n", r.frame, r.t);
    csv << line;
  }
  int found = 0;
  for (const TrackRow& r : result.rows) found += r.ball.found;
  nlohmann::ordered_json side = {{"format", "uphill-track/1"},
                                 {"video", sources.video},
                                 {"camera", sources.camera},
                                 {"scene", sources.scene},
                                 {"body", sources.body},
                                 {"frames", result.rows.size()},
                                 {"declared_frames", result.declared_frames},
                                 {"frames_with_ball", found},
                                 {"fps", result.fps},
                                 {"extrapolated_timestamps", result.extrapolated_times},
                                 {"time", result.readout > 0
                                              ? "the container's timestamp of the frame plus the rolling shutter's "
                                                "delay of the row where the centre lies: its mid-exposure"
                                              : "the container's timestamp of the frame: the mid-exposure"},
                                 {"transfer", result.transfer == VideoTransfer::kLinear ? "linear" : "sRGB"},
                                 {"readout_s", result.readout},
                                 {"partial", result.partial}};
  if (result.measured_readout_frames > 0) side["readout_measured_frames"] = result.measured_readout_frames;
  if (result.readout_u) {
    side["readout_u_s"] = *result.readout_u;
    side["image_height_px"] = result.image_height;
  }
  if (result.exposure) side["exposure_s"] = *result.exposure;
  else if (result.measured_exposure) {
    side["exposure_s"] = *result.measured_exposure;
    side["exposure_measured_frames"] = result.measured_exposure_frames;
  } else {
    side["exposure_s"] = nullptr;
  }
  if (!result.exposure_changes.empty()) side["exposure_changes_at_frames"] = result.exposure_changes;
  // The models the clip needed, as chosen from it (ball_tracker.hpp, "Model only what the scene
  // needs"); the flags that override each: docs/track.md, "Output".
  int outline_model = 0;
  for (const TrackRow& r : result.rows) outline_model += r.ball.found && r.ball.full_model;
  side["models"] = {
      {"exposure", result.exposure ? "given" : result.measured_exposure ? "measured" : "assumed half a frame"},
      {"rolling_shutter", result.measured_readout_frames > 0 ? "measured"
                          : result.readout_asked             ? "not measurable (too little shear): half a frame assumed"
                          : result.readout > 0               ? "given"
                                                             : "global"},
      {"frames_by_edge_fit", found - outline_model},
      {"frames_by_outline_model", outline_model},
      {"frames_left_off_the_path", result.frames_left_off_path},
      {"frames_left_out_of_poor_fit", result.frames_of_poor_fit}};
  if (result.partial) side["partial_reason"] = result.partial_reason;
  OutputPaths::CreateFolders(std::filesystem::path(csv_path).parent_path().string());
  WriteFileAtomically(csv_path, csv.str());
  WriteFileAtomically(csv_path + ".json", side.dump(2) + "\n");
}

}  // namespace uphill
