// The calibration and video part of the server's API (http_server.hpp lists the routes): the
// answers computed from the store's state and the folder's files. Private to src/server/.
// Each function throws InputError (422, naming the field) for what the request or the folder's
// files get wrong, EnvironmentError for the server's own folder; the caller maps them.
// Lengths in requests and answers are plain numbers in the experiment's unit; pixels are raw
// pixels of the video's frames (OpenCV's convention: (0, 0) the centre of the top-left pixel).
#pragma once

#include <nlohmann/json.hpp>
#include <chrono>
#include <string>

#include "app/video_frames.hpp"
#include "server/experiment_store.hpp"

namespace uphill::internal {

// The absolute path of a regular file of the experiment folder, reached without links (for the
// libraries that open paths). Throws InputError(field) when it is not there or not a file.
std::string FolderFile(const ExperimentStore& store, const std::string& relative, const std::string& field);

// GET /api/video/frame?video=P&frame=N&format=png|jpeg: the decode leases its bytes of `budget`,
// waiting at most `wait` (DecodeBusy: 503).
EncodedFrame VideoFrame(const ExperimentStore& store, const std::string& video, int frame, bool jpeg,
                        DecodeBudget& budget, std::chrono::milliseconds wait);

// GET /api/video/info?video=P: {video, width, height, fps, frames} as the container states them
// (app/video_frames.hpp ProbeVideo), for the page's player. Throws ProbeVideo's InputError.
nlohmann::ordered_json VideoInfo(const ExperimentStore& store, const std::string& video);

// A scene file that does not fit the video's size is refused when the video is attached (the
// track would be wrong everywhere): the row's `scene`, or the experiment's only scene. Throws
// InputError("video") naming both sizes, the scene and its file.
void CheckSceneFits(const StoreSnapshot& snapshot, std::string scene, const std::string& video, const VideoProbe& probe);

// GET /api/videos: {videos:[{path, bytes}]} the video files in the folder (by extension, at most
// 3 folders deep, links not followed), sorted.
nlohmann::ordered_json ListVideos(const ExperimentStore& store);

// GET /api/scene/points?row=ID&table_z=Z&marks=M1,M2: {points:[{name,x,y,z}]}, the apparatus
// points of the row's setting (app/scene_clicks.hpp), or only O when the row gives no L, H, D.
nlohmann::ordered_json ScenePoints(const StoreSnapshot& snapshot, const nlohmann::json& query);

// POST /api/scene/solve {video, frame?, row?, clicks:[{name,u,v,x,y,z}], unclicked?:[{name,x,y,z}],
// marks?:[x...], table_z?}: the pose from the clicks (app/scene_clicks.hpp) with the experiment's
// camera file: {rms_px, verdict, reasons, leave_one_out:{name, residual_px, rms_without_px,
// explains} or null (vision/calibration.hpp), points:[{name,u,v,u_model,v_model,residual_px}],
// expected:[{name,u,v}] (the unclicked points in view), axes:[{name,u,v}] (O, +x, +y in view),
// path:[[u,v]...], camera_centre:{x,y,z}}. `scene_file` (optional) receives the scene file's text, which keeps
// the clicks, the marks and the table's height.
nlohmann::ordered_json SolveScene(const ExperimentStore& store, const StoreSnapshot& snapshot,
                                  const nlohmann::json& body, std::string* scene_file = nullptr);

// GET /api/scenes/NAME: what the saved scene `name` was solved from, for the page to restore:
// {name, path, points:[{name,u,v,x,y,z}], marks:[x...], table_z (null: not kept), unit}; a scene
// file that keeps none of it gives empty lists. Throws InputError("name") when the experiment
// has no such scene, its name breaks SceneFilePath's rule or its file is not there; the file's own
// InputError when it is malformed.
nlohmann::ordered_json SavedScene(const StoreSnapshot& snapshot, const std::string& name);

// The scene's file in the folder: calibration/scene-<name>.json. Throws InputError("name")
// unless the name is 1 to 32 letters, digits, '-' or '_'.
std::string SceneFilePath(const std::string& name);

// A chessboard view uploaded (PUT /api/views/NAME): its size when OpenCV decodes it. Throws
// InputError(name) naming the rule when its header declares more pixels than uphill decodes
// (vision/decode_limits.hpp; checked before decoding) or it does not decode as an image.
struct ImageSize {
  int width = 0, height = 0;
};
ImageSize ProbeImage(const std::string& path, const std::string& name);

// POST /api/camera/calibrate {folder, cols, rows, square}: CalibrateCamera over the images (.png,
// .jpg, .jpeg, .bmp, .tif) of a folder of the experiment; `camera_file` receives the camera file's
// text: {verdict, reasons, rms_px, views_used, coverage, fx, fy, cx, cy, width, height,
// views:[{name, used, rejected_because, rms_px, tilt_deg}]}.
nlohmann::ordered_json CalibrateCameraViews(const ExperimentStore& store, const StoreSnapshot& snapshot,
                                            const nlohmann::json& body, std::string* camera_file);

}  // namespace uphill::internal
