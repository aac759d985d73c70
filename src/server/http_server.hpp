// Server: the HTTP side of `uphill serve` (cpp-httplib). Serves the page (page_assets.hpp, all
// embedded: it works offline) and a JSON API over one ExperimentStore.
//
// API (JSON bodies; lengths as plain-number text in the experiment's unit, see docs/serve.md, "The JSON API"):
//   GET    /api/state                     the state (below)
//   PUT    /api/experiment                {version, experiment, unit}: create or change
//   POST   /api/rows                      {version, row, index?}: add a row
//   PUT    /api/rows/<id>                 {version, row}: replace a row
//   DELETE /api/rows/<id>                 {version}: delete a row
//   POST   /api/undo                      {version}: undo the last change
//   POST   /api/check                     {row}: check a draft row (nothing stored)
//   POST   /api/report                    {}: write the fit report to EXP/report/
//   POST   /api/fit-xy                    {method, x, y, u_x?, u_y?}: `uphill fit --xy --json`'s JSON
//   GET    /report/<name>                 a file of EXP/report/, read-only
// Videos and calibration (internal/calibration_api.hpp says what each answers):
//   GET    /api/videos                    the video files in the folder
//   PUT    /api/videos/<name>             the body (application/octet-stream, at most
//                                         max_upload_bytes) becomes EXP/videos/<name>, atomically
//   PUT    /api/views/<name>              the body (application/octet-stream, an image, at most
//                                         max_view_upload_bytes) becomes EXP/calibration/views/<name>
//   GET    /api/video/info?video=P         its size, frame rate and frame count
//   GET    /api/video/frame?video=P&frame=N[&format=jpeg]   a frame as PNG (or JPEG)
//   POST   /api/rows/<id>/video           {version, video}: attach a video of the folder to a row
//   POST   /api/rows/<id>/detach          {version}: clear the row's video; the file is moved to
//                                         EXP/.detached/ (out of the list) unless another row uses it
//   GET    /api/scene/points?row=ID[&table_z=Z&marks=M,M]   the apparatus points to click
//   POST   /api/scene/solve               {video, row?, clicks, marks?, table_z?}: the pose,
//                                         residuals, the leave-one-out check, the path
//   POST   /api/rows/<id>/track           {}: the trial's video tracked and analysed (cached)
//   POST   /api/rows/<id>/accept-y        {version}: the video's rest position becomes Y ± u_Y
//   PUT    /api/scenes/<name>             {version, video, row?, clicks, marks?, table_z?}: solve
//                                         and save the scene file calibration/scene-<name>.json
//                                         (it keeps the clicks, the marks and the table's height)
//   GET    /api/scenes/<name>             what the saved scene was solved from (to restore it)
//   POST   /api/camera/calibrate          {version, folder, cols, rows, square}: the camera file
//                                         calibration/camera.json from chessboard views
// The state: {version, can_undo, directory, exists, experiment, unit, columns, rows:[{id, trial,
// series, L, H, D, Y, u_*, note, check:{theta_deg, alpha_deg, x, u_x, x_max, crossbar, y,
// residual, flags:[{code, field, message, severity}]}}], fit:{...}, report:{exists, url},
// journal:{status: "ok"|"damaged", message}}.
// Errors: {error, field?}: 400 malformed JSON, a missing version, a header given twice or a
// request that cannot be parsed; 403 a request from another origin or host, a refused report
// name, or a link or non-regular file where the report lives; 404; 408 a request that did not
// arrive within the deadline or an upload that stalled; 409 a stale version ({error, state}: the
// current state); 411 a body without Content-Length (chunked); 413 a request over
// max_request_bytes; 415 a body that is not exactly application/json; 422 content that breaks a
// rule (text that is not UTF-8 included, a file larger than the pixel limit), naming the field;
// 500 the server's own folder or disk failed (full included); 503 too many uploads at once, or
// frames to decode beyond the decode budget (try again).
//
// Security (docs/serve.md, "What the server promises", says what is promised and what is not): by default bound to
// 127.0.0.1; the Host header must name the loopback address (no DNS rebinding); changes need
// Content-Type application/json and, if the browser sends Origin, this server's own origin (no
// cross-site requests); every response carries a strict Content-Security-Policy (scripts and
// styles only from this server, no inline code), and the page inserts user text with textContent
// only. Files are read and written only inside the experiment folder, never through a link
// (io/contained_directory.hpp); every request is bounded in bytes and time and idle connections
// hold no one up (internal/bounded_http_server.hpp).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "app/analysis_defaults.hpp"
#include "server/experiment_store.hpp"

namespace uphill {

struct ServerOptions {
  std::string directory;               // the experiment folder (created with the experiment)
  std::string host = "127.0.0.1";
  int port = 8080;                     // 0: any free port (Bind returns it)
  std::size_t max_request_bytes = 64 * 1024;  // a request's body; its headers get 32 KiB more
  std::size_t max_upload_bytes = std::size_t{2} << 30;  // an uploaded video
  std::size_t max_view_upload_bytes = std::size_t{64} << 20;  // an uploaded chessboard view
  std::chrono::milliseconds upload_deadline{30 * 60 * 1000};  // for the whole upload
  // An upload that sends no byte for upload_idle_timeout is closed and its partial file removed
  // (408); at most max_concurrent_uploads are received at once (more: 503, body unread), so
  // stalled uploads hold up neither other uploads for long nor any other request.
  std::chrono::milliseconds upload_idle_timeout{30 * 1000};
  std::size_t max_concurrent_uploads = 8;
  // Frame requests lease their decoded bytes (app/video_frames.hpp FrameDecodeBytes) of this
  // budget, waiting at most frame_decode_wait for it (503 after that, or at once for a frame
  // larger than the whole budget); the pixel limit itself: vision/decode_limits.hpp.
  std::size_t frame_decode_budget_bytes = std::size_t{512} << 20;
  std::chrono::milliseconds frame_decode_wait{10 * 1000};
  // Per row, for u(X) by Monte Carlo in the report: the app's default, so that the page's report
  // is `uphill report`'s.
  std::uint64_t report_mc_trials = kAnalysisMonteCarloTrials;
  // A request must arrive whole within request_deadline; a connection idle for idle_timeout is
  // closed; at most max_connections are served at once (one thread each).
  std::chrono::milliseconds request_deadline{10000};
  std::chrono::milliseconds idle_timeout{5000};
  std::size_t max_connections = 128;
};

class Server {
 public:
  // Opens the experiment (ExperimentStore: checks the folder and may throw EnvironmentError or
  // InputError before anything listens).
  explicit Server(ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens; returns the port. Throws EnvironmentError naming the port when it is taken
  // (never shared: no SO_REUSEPORT) or the address is not this computer's.
  int Bind();
  // Serves until Stop() (from another thread). Call after Bind.
  void Run();
  // Stops listening: Run() returns once the connections being served are answered. Safe at any
  // time and more than once, from any thread: a Stop() that comes before Run() (or before
  // Bind()) makes Run() return at once.
  void Stop();

  ExperimentStore& store();

  // The most bytes read for one request so far (request line, headers and body): what the
  // per-request byte budget bounds (internal/bounded_http_server.hpp).
  std::size_t largest_request_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill
