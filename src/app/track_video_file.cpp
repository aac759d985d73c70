#include "app/track_video_file.hpp"

#include "app/tracking_inputs.hpp"
#include "app/video_frames.hpp"
#include "model/input_error.hpp"

namespace uphill {

VideoTransfer ParseVideoTransfer(const std::string& name, const std::string& quantity) {
  if (name == "srgb") return VideoTransfer::kSrgb;
  if (name == "linear") return VideoTransfer::kLinear;
  throw InputError(quantity, "must be srgb or linear (got '" + name + "')");
}

TrackResult TrackVideoFile(const std::string& video, const std::string& camera_file, const std::string& scene_file,
                           const Scene& scene, const TrackVideoFileOptions& options,
                           const FrameProgressCallback& progress) {
  if (scene.body().kind == BodyKind::kDoubleCone) throw InputError("body", kDoubleConeRefusal);
  const SceneCalibration calibration = ReadTrackingCalibration(camera_file, scene_file);
  ProbeVideo(video, options.video_label.empty() ? video : options.video_label);  // a video, within the pixel limit
  TrackVideoOptions track;
  track.calibration_name = options.scene_label.empty() ? scene_file : options.scene_label;
  track.overlay_path = options.overlay_path;
  track.progress = progress;
  track.tracker.init_uv = options.init_uv;
  track.tracker.exposure = options.exposure;
  track.tracker.readout = options.readout;
  track.tracker.measure_readout = options.measure_readout;
  track.tracker.transfer = options.transfer;
  track.tracker.min_report_quality = options.min_report_quality;
  return TrackVideo(video, scene, calibration, track);
}

}  // namespace uphill
