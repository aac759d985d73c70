// The robustness table of `uphill bench track`: the tracker on the ray-traced footage
// of src/footage/footage_conditions.hpp, one row per condition, against OpenCV's CSRT, KCF and
// HoughCircles on the same clips (tools/bench/track_peers.py).
//
// Each clip goes the user's way: `calibrate camera` on its chessboard views (CalibrateCamera),
// `calibrate scene` on its apparatus points (CalibrateScene), then TrackVideo with that
// calibration. Scored against the renderer's truth over the frames where the body is at least
// half visible: RMS of (u, v) in px, of (x, z) in mm, and the frames found of those frames. The
// peers start from the true box of the first frame (an advantage over uphill, which searches) and
// report pixels; their (x, z) is where the calibrated viewing ray of their pixel meets the plane
// y = 0 of the body's centre. Clips of bad input get their own table: what uphill said (error,
// partial and why, or nothing), the frames where it reported a body, and those where there was none.
// The clips are rendered once into the footage cache (footage_clip.hpp); the table says how long
// each took to render.
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "bench/results_document.hpp"

namespace uphill::bench {

struct TrackMatrixOptions {
  std::string cache;                    // footage cache; "" = FootageCacheRoot()
  std::vector<std::string> conditions;  // names; empty = the whole matrix
  bool fresh = false;                   // render again
  std::string python, script;           // the peers (script "" = skip them, why_not says why)
  std::string why_not_peers;
  std::string positions;  // folder for each clip's frames against the truth ("" = none); see below
};

// The tables (kept alive until the section is recorded) and the notes of the run.
struct TrackMatrixRecord {
  Table robustness{{}};
  Table bad_input{{}};
  std::vector<std::string> notes;
};

// With `positions` set, each clip's frames are written to <positions>/<condition>.csv: frame,
// found, full_model, the tracker's u, v (px) and x, z (mm), and the renderer's true u_true,
// v_true, x_true, z_true and visibility, so that an error can be followed frame by frame.
// Renders or reuses the clips, tracks them, runs the peers, prints both tables to `out` as rows
// are measured. Throws std::runtime_error when povray or ffmpeg is missing (the clips cannot be made).
std::unique_ptr<TrackMatrixRecord> RunTrackMatrix(const TrackMatrixOptions& options, std::ostream& out);

// The method paragraph of the robustness table (Markdown).
extern const char* const kTrackMatrixMethod;

}  // namespace uphill::bench
