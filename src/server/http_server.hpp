// Server: the HTTP side of `uphill serve` (cpp-httplib). Serves the page (page_assets.hpp, all
// embedded: it works offline) and a JSON API over one ExperimentStore.
//
// API (JSON bodies; lengths as plain-number text in the experiment's unit, see README.md):
//   GET    /api/state                     the state (below)
//   PUT    /api/experiment                {version, experiment, unit}: create or change
//   POST   /api/rows                      {version, row, index?}: add a row
//   PUT    /api/rows/<id>                 {version, row}: replace a row
//   DELETE /api/rows/<id>                 {version}: delete a row
//   POST   /api/undo                      {version}: undo the last change
//   POST   /api/check                     {row}: check a draft row (nothing stored)
//   POST   /api/report                    {}: write the fit report to EXP/report/
//   GET    /report/<name>                 a file of EXP/report/, read-only
// The state: {version, can_undo, directory, exists, experiment, unit, columns, rows:[{id, trial,
// series, L, H, D, Y, u_*, note, check:{theta_deg, alpha_deg, x, u_x, x_max, crossbar, y,
// residual, flags:[{code, field, message, severity}]}}], fit:{...}, report:{exists, url}}.
// Errors: {error, field?}: 400 malformed JSON or missing version, 403 a request from another
// origin or host, or a refused report name, 404, 409 a stale version ({error, state}: the
// current state), 413 a request over max_request_bytes, 422 content that breaks a rule, 500.
//
// Security: by default bound to 127.0.0.1; the Host header must name the loopback address (no
// DNS rebinding); changes need Content-Type application/json and, if the browser sends Origin,
// this server's own origin (no cross-site requests); every response carries a strict
// Content-Security-Policy (scripts and styles only from this server, no inline code), and the page
// inserts user text with textContent only.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "server/experiment_store.hpp"

namespace uphill {

struct ServerOptions {
  std::string directory;               // the experiment folder (created with the experiment)
  std::string host = "127.0.0.1";
  int port = 8080;                     // 0: any free port (Bind returns it)
  std::size_t max_request_bytes = 64 * 1024;
  std::uint64_t report_mc_trials = 10000;  // per row, for u(X) by Monte Carlo in the report
};

class Server {
 public:
  // Opens the experiment (ExperimentStore: may throw).
  explicit Server(ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens; returns the port. Throws std::runtime_error if the address is taken.
  int Bind();
  // Serves until Stop() (from another thread). Call after Bind.
  void Run();
  void Stop();

  ExperimentStore& store();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill
