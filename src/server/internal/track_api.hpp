// The tracking part of the server's API (http_server.hpp lists the routes): a trial's video
// tracked and analysed by the use case of app/video_trials.hpp (cached in EXP/.uphill-cache/).
// Private to src/server/. Lengths in the experiment's unit.
#pragma once

#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "server/experiment_store.hpp"

namespace uphill::internal {

// POST /api/rows/<id>/track: {row, video, frames, frames_tracked, partial, partial_reason,
// release: {x0: {value, u}, t0: {value, u}}, direction, turns: [{x, t}], rest: {y: {value, u}, t},
// never_at_rest, fit: {text}, warnings, width, height, strip: [{frame, t, u, v, radius_px, x}]}
// (8 frames spread over the clip; u, v, x null where the body was not found). Throws
// InputError("video") with the trial's own message (not a video, a scene of another size, the
// body never found ...).
nlohmann::ordered_json TrackRowVideo(const ExperimentStore& store, const StoreSnapshot& snapshot, std::int64_t id);

// The row's video's rest position as the row's Y and u_Y (plain numbers in the unit, 6
// significant digits). Throws InputError("video") when the video has no rest (why).
struct RestAsY {
  std::string y, u_y;
};
RestAsY RowRestAsY(const ExperimentStore& store, const StoreSnapshot& snapshot, std::int64_t id);

// The folder where detached videos are kept: hidden, so that GET /api/videos (which skips folders
// starting with '.') no longer lists them, and no video of the experiment is ever deleted.
inline constexpr const char* kDetachedVideoFolder = ".detached";

// POST /api/rows/<id>/detach: empties the row's video cell (a journaled edit, against `version`),
// then, holding `track_mutex` (no track reads the file meanwhile), moves the file into
// kDetachedVideoFolder (as its file name, "-2", "-3"... before the extension when taken) unless
// another row still names it. Throws InputError for a row that does not exist, has no video, or
// has no Y (without its video it would measure nothing), VersionConflict as the store, and
// EnvironmentError when the move fails (the row is then detached, the file still listed).
struct DetachedVideo {
  std::string video;     // the path the row named
  std::string moved_to;  // the file's new path in the folder, "" when left in place (still used)
  StoreSnapshot after;   // the state with the cell emptied
};
DetachedVideo DetachRowVideo(ExperimentStore& store, std::int64_t version, std::int64_t id, std::mutex& track_mutex);

}  // namespace uphill::internal
