#include "server/http_server.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
#include <cstring>
#include <optional>
#include <regex>
#include <sstream>
#include <tuple>
#include <type_traits>

#include "app/experiment_folder_analysis.hpp"
#include "io/contained_directory.hpp"
#include "io/experiment.hpp"
#include "io/utf8.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "report/analysis.hpp"
#include "report/fit_document.hpp"
#include "report/report_outputs.hpp"
#include "vision/camera.hpp"
#include "internal/calibration_api.hpp"
#include "internal/fit_api.hpp"
#include "internal/folder_claim.hpp"
#include "internal/page_assets.hpp"
#include "internal/request_values.hpp"
#include "internal/track_api.hpp"
#include "internal/video_upload.hpp"
#include "server/row_check.hpp"
// Last: they include <httplib.h>, which includes <resolv.h>, whose `_res` macro breaks Eigen.
#include "internal/bounded_http_server.hpp"
#include "internal/http_replies.hpp"
#include "internal/request_gate.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;
using internal::ContentType;
using internal::IsJsonContentType;
using internal::ParseBody;
using internal::Refuse;
using internal::SecurityHeaders;
using internal::SendError;
using internal::SendJson;
using internal::VersionOf;

constexpr std::size_t kMaxReportFileBytes = 64u << 20;

// Report files are documents, not the app: no script at all, their own inline styles, sandboxed.
constexpr const char* kReportPolicy =
    "default-src 'none'; img-src 'self' data:; style-src 'unsafe-inline'; frame-ancestors 'none'; sandbox";

// The routes whose body is not JSON: uploads, streamed to disk (internal/video_upload.hpp). The
// pre-routing handler (internal/request_gate.hpp) sends every PUT under these prefixes through
// the upload's checks (its name first), so a name the route's pattern does not match is refused
// by the name's rule.
constexpr const char* kVideoUploadPattern = R"(/api/videos/([^/]{1,120}))";
constexpr const char* kViewUploadPattern = R"(/api/views/([^/]{1,120}))";


// Every field a request got wrong: {"error", "field"} of the first (as SendError) and
// "errors": [{"field", "error"}] of them all, so the page names and highlights each.
void SendFieldErrors(httplib::Response& res, const FieldErrors& e) {
  ordered_json body = {{"error", e.what()}, {"field", e.quantity()}, {"errors", ordered_json::array()}};
  for (const InputError& one : e.errors()) body["errors"].push_back({{"field", one.quantity()}, {"error", one.rule()}});
  SendJson(res, 422, body);
}

std::string Seconds(std::chrono::milliseconds t) {
  std::ostringstream out;
  out << t.count() / 1000.0 << " s";
  return out.str();
}

// At most `max` uploads at once: a slot is held from the upload's start to its end.
class UploadSlot {
 public:
  UploadSlot(std::atomic<std::size_t>& count, std::size_t max) : count_(count), held_(++count_ <= max) {
    if (!held_) --count_;
  }
  ~UploadSlot() {
    if (held_) --count_;
  }
  UploadSlot(const UploadSlot&) = delete;
  UploadSlot& operator=(const UploadSlot&) = delete;
  bool held() const { return held_; }

 private:
  std::atomic<std::size_t>& count_;
  const bool held_;
};

bool ValidReportName(const std::string& name) {
  static const std::regex ok("[A-Za-z0-9][A-Za-z0-9._-]{0,127}");
  return std::regex_match(name, ok) && name.find("..") == std::string::npos;
}




internal::ConnectionLimits Limits(const ServerOptions& options) {
  internal::ConnectionLimits limits;
  limits.request_budget_bytes = options.max_request_bytes + 32 * 1024;  // the body and its headers
  limits.request_deadline = options.request_deadline;
  limits.idle_timeout = options.idle_timeout;
  limits.max_connections = options.max_connections;
  return limits;
}


}  // namespace

struct Server::Impl {
  ServerOptions options;
  ExperimentStore store;
  internal::BoundedHttpServer http;
  int port = 0;
  std::mutex report_mutex;
  std::atomic<bool> stopped{false};  // Stop() was called: Run() no longer listens
  std::mutex claim_mutex;
  std::optional<internal::FolderClaim> claim;  // once the folder exists (internal/folder_claim.hpp)
  std::atomic<std::size_t> uploads{0};         // being received (UploadSlot)
  DecodeBudget frame_budget{options.frame_decode_budget_bytes};  // frame requests' decoded bytes

  explicit Impl(ServerOptions o) : options(std::move(o)), store(options.directory), http(Limits(options)) {
    ClaimFolder();
  }

  // Holds the experiment folder as one of its servers, from start or from when it is created;
  // the first server on it removes the staging folders a killed server left. Before staging.
  void ClaimFolder() {
    std::lock_guard lock(claim_mutex);
    if (claim) return;
    if (const ContainedDirectory* folder = store.folder()) claim.emplace(*folder);
  }

  // Whether EXP/report/report.html is there (a regular file, reached without links).
  bool ReportExists() const {
    const ContainedDirectory* folder = store.folder();
    if (!folder) return false;
    try {
      return folder->KindOf("report/report.html") == ContainedDirectory::Kind::kFile;
    } catch (const std::exception&) {
      return false;
    }
  }

  ordered_json StateJson(const StoreSnapshot& s) const {
    ordered_json j;
    j["version"] = s.version;
    j["can_undo"] = s.can_undo;
    j["directory"] = store.directory();
    j["exists"] = s.state.exists;
    j["experiment"] = s.state.metadata.is_object() ? s.state.metadata : ordered_json::object();
    j["unit"] = s.state.unit;
    j["columns"] = s.state.Columns();
    const ordered_json checked = CheckAll(s.state);
    j["rows"] = ordered_json::array();
    for (std::size_t i = 0; i < s.state.rows.size(); ++i) {
      ordered_json row = ToJson(s.state.rows[i]);
      ordered_json check = checked["checks"][i];
      check.erase("id");
      row["check"] = check;
      j["rows"].push_back(row);
    }
    j["fit"] = checked["fit"];
    const bool report = ReportExists();
    j["report"] = {{"exists", report}, {"url", report ? json("/report/report.html") : json(nullptr)}};
    const JournalStatus journal = store.journal_status();
    j["journal"] = {{"status", journal.damaged ? "damaged" : "ok"}, {"message", journal.message}};
    return j;
  }

  // Runs a change: maps every outcome to its status code; success returns the new state.
  template <class Change>
  void Mutate(const httplib::Request& req, httplib::Response& res, Change change, bool state_answer = true) {
    try {
      const json body = ParseBody(req);
      if constexpr (std::is_same_v<decltype(change(body)), StoreSnapshot>) {
        SendJson(res, 200, StateJson(change(body)));
      } else {
        (void)state_answer;
        SendJson(res, 200, change(body));
      }
    } catch (const VersionConflict& e) {
      SendJson(res, 409, {{"error", e.what()}, {"state", StateJson(e.current())}});
    } catch (const FieldErrors& e) {
      SendFieldErrors(res, e);
    } catch (const InputError& e) {
      SendError(res, 422, e.what(), e.quantity());
    } catch (const json::exception& e) {
      SendError(res, 400, std::string("malformed JSON: ") + e.what());
    } catch (const std::invalid_argument& e) {
      SendError(res, 400, e.what());
    } catch (const EnvironmentError& e) {
      SendError(res, 500, e.what());  // the server's disk or folder, not the request
    } catch (const std::exception& e) {
      SendError(res, 500, std::string("internal error: ") + e.what());
    }
  }


  void Routes() {
    internal::GuardRequests(http, options, port);

    for (const PageAsset& asset : PageAssets()) {
      const auto serve = [asset](const httplib::Request&, httplib::Response& res) {
        res.set_content(std::string(asset.content), asset.content_type);
      };
      http.Get(asset.path, serve);
      if (std::string(asset.path) == "/index.html") http.Get("/", serve);
    }

    // Browsers ask for it on their own; "no content" keeps their console free of 404s.
    http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
    http.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
      SendJson(res, 200, StateJson(store.Get()));
    });
    http.Put("/api/experiment", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this](const json& b) {
        const std::int64_t version = VersionOf(b);
        if (!b.contains("unit") || !b.at("unit").is_string()) throw InputError("unit", "is missing");
        return store.SetMetadata(version, b.value("experiment", json::object()), b.at("unit").get<std::string>());
      });
    });
    http.Post("/api/rows", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this](const json& b) {
        const std::int64_t version = VersionOf(b);
        std::optional<std::int64_t> index;
        if (b.contains("index") && b.at("index").is_number_integer()) index = b.at("index").get<std::int64_t>();
        return store.AddRow(version, b.value("row", json::object()), index);
      });
    });
    http.Post("/api/rows/import", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this](const json& b) { return store.AddRows(VersionOf(b), b.value("rows", json())); });
    });
    http.Put(R"(/api/rows/(\d{1,12}))", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this, &req](const json& b) {
        return store.EditRow(VersionOf(b), std::stoll(req.matches[1].str()), b.value("row", json::object()));
      });
    });
    http.Delete(R"(/api/rows/(\d{1,12}))", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this, &req](const json& b) {
        return store.DeleteRow(VersionOf(b), std::stoll(req.matches[1].str()));
      });
    });
    http.Post("/api/undo", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this](const json& b) { return store.Undo(VersionOf(b)); });
    });
    http.Post("/api/check", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this](const json& b) { return CheckAnswer(store.Get().state, b.value("row", json::object())); });
    });
    http.Post("/api/report", [this](const httplib::Request&, httplib::Response& res) {
      std::lock_guard lock(report_mutex);  // one report at a time; the store stays free meanwhile
      try {
        WriteReport(res);
      } catch (const InputError& e) {
        SendError(res, 422, e.what(), e.quantity());
      } catch (const std::exception& e) {
        SendError(res, 500, e.what());
      }
    });
    VideoRoutes();
    http.Post("/api/fit-xy", [this](const httplib::Request& req, httplib::Response& res) { Respond(req, res, internal::FitXyAnswer); });
    http.Get("/report/(.*)", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string name = req.matches[1].str();
      if (!ValidReportName(name)) {
        SendError(res, 403, "refused: report files are served by plain name only");
        return;
      }
      const ContainedDirectory* folder = store.folder();
      try {
        const std::string relative = "report/" + name;
        const auto kind = folder ? folder->KindOf(relative) : ContainedDirectory::Kind::kAbsent;
        if (kind == ContainedDirectory::Kind::kAbsent) {
          SendError(res, 404, "no such report file: " + name);
          return;
        }
        if (kind != ContainedDirectory::Kind::kFile) {
          SendError(res, 403, "refused: " + name + " is not a regular file of the report folder");
          return;
        }
        const auto content = folder->ReadFile(relative, kMaxReportFileBytes);
        if (!content) {
          SendError(res, 404, "no such report file: " + name);
          return;
        }
        res.set_header("Content-Security-Policy", kReportPolicy);
        res.set_content(*content, ContentType(name));
      } catch (const EnvironmentError& e) {
        // A link at report/ or at the file: nothing outside the experiment folder is served.
        SendError(res, 403, std::string("refused: ") + e.what());
      }
    });
  }

  // Runs a request that answers JSON (no change): maps every outcome to its status code.
  template <class Answer>
  void Respond(const httplib::Request& req, httplib::Response& res, Answer answer) {
    Mutate(req, res, [&](const json& body) -> ordered_json { return answer(body); }, false);
  }

  void VideoRoutes() {
    http.Get("/api/videos", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this](const json&) { return internal::ListVideos(store); });
    });
    http.Get("/api/video/info", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this, &req](const json&) { return internal::VideoInfo(store, req.get_param_value("video")); });
    });
    http.Get("/api/video/frame", [this](const httplib::Request& req, httplib::Response& res) {
      try {
        const int frame = req.has_param("frame")
                              ? static_cast<int>(internal::WholeNumberText(req.get_param_value("frame"), "frame", 0,
                                                                           999'999'999, "a frame number (0 = the first)"))
                              : 0;
        const EncodedFrame image = internal::VideoFrame(store, req.get_param_value("video"), frame,
                                                        req.get_param_value("format") == "jpeg", frame_budget,
                                                        options.frame_decode_wait);
        res.set_header("X-Frame-Index", std::to_string(image.index));
        res.set_header("X-Video-Size", std::to_string(image.video.width) + "x" + std::to_string(image.video.height));
        res.set_header("X-Video-Frames", std::to_string(image.video.frames));
        res.set_content(image.bytes, image.content_type);
      } catch (const InputError& e) {
        SendError(res, 422, e.what(), e.quantity());
      } catch (const DecodeBusy& e) {
        SendError(res, 503, e.what(), "frame");
      } catch (const std::exception& e) {
        SendError(res, 500, e.what());
      }
    });
    http.Get("/api/scene/points", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this, &req](const json&) {
        json query = json::object();
        if (req.has_param("row"))
          query["row"] = internal::WholeNumberText(req.get_param_value("row"), "row", 1, 999'999'999'999, "a row id");
        if (req.has_param("table_z")) query["table_z"] = internal::NumberText(req.get_param_value("table_z"), "table_z");
        if (req.has_param("marks")) {
          query["marks"] = json::array();
          std::stringstream in(req.get_param_value("marks"));
          for (std::string item; std::getline(in, item, ',');)
            if (!item.empty()) query["marks"].push_back(internal::NumberText(item, "marks"));
        }
        return internal::ScenePoints(store.Get(), query);
      });
    });
    http.Post("/api/scene/solve", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this](const json& b) { return internal::SolveScene(store, store.Get(), b); });
    });
    http.Put(R"(/api/scenes/([^/]{1,64}))", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this, &req](const json& b) {
        const std::int64_t version = VersionOf(b);
        const std::string name = req.matches[1].str();
        const std::string path = internal::SceneFilePath(name);
        std::string text;
        internal::SolveScene(store, store.Get(), b, &text);
        return store.SaveCalibrationFile(version, "scene", name, path, text);
      });
    });
    http.Get(R"(/api/scenes/([^/]{1,64}))", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this, &req](const json&) { return internal::SavedScene(store.Get(), req.matches[1].str()); });
    });
    http.Post("/api/camera/calibrate", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this](const json& b) {
        const std::int64_t version = VersionOf(b);
        std::string text;
        ordered_json calibration = internal::CalibrateCameraViews(store, store.Get(), b, &text);
        const StoreSnapshot s = store.SaveCalibrationFile(version, "camera", "", "calibration/camera.json", text);
        return ordered_json{{"calibration", calibration}, {"state", StateJson(s)}};
      });
    });
    // Tracking reads the files as saved, outside the store's lock; one at a time (with reports).
    http.Post(R"(/api/rows/(\d{1,12})/track)", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this, &req](const json&) {
        std::lock_guard lock(report_mutex);
        return internal::TrackRowVideo(store, store.Get(), std::stoll(req.matches[1].str()));
      });
    });
    http.Post(R"(/api/rows/(\d{1,12})/accept-y)", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this, &req](const json& b) {
        const std::int64_t version = VersionOf(b);
        const std::int64_t id = std::stoll(req.matches[1].str());
        const StoreSnapshot s = store.Get();
        internal::RestAsY rest;
        {
          std::lock_guard lock(report_mutex);
          rest = internal::RowRestAsY(store, s, id);
        }
        ordered_json row = ToJson(s.state.rows[s.state.IndexOf(id)]);
        row["Y"] = rest.y;
        if (!rest.u_y.empty()) row["u_Y"] = rest.u_y;
        return store.EditRow(version, id, row);
      });
    });
    // A row id, or "new": a new trial (body `trial`: its label) with this video.
    http.Post(R"(/api/rows/(\d{1,12}|new)/video)", [this](const httplib::Request& req, httplib::Response& res) {
      Mutate(req, res, [this, &req](const json& b) {
        const std::int64_t version = VersionOf(b);
        const StoreSnapshot s = store.Get();
        const bool add = req.matches[1].str() == "new";
        const std::int64_t id = add ? 0 : std::stoll(req.matches[1].str());
        const int index = add ? -1 : s.state.IndexOf(id);
        if (!add && index < 0) throw InputError("row", "row " + std::to_string(id) + " does not exist");
        ordered_json row = add ? ordered_json{{"trial", b.value("trial", json("")).is_string() ? b.value("trial", "") : ""}}
                               : ToJson(s.state.rows[index]);
        const std::string video = b.value("video", json("")).is_string() ? b.value("video", "") : "";
        if (video.empty()) {
          if (add) throw InputError("video", "is missing");
          row.erase("video");
        } else {
          const VideoProbe probe = ProbeVideo(internal::FolderFile(store, video, "video"), video);
          internal::CheckSceneFits(s, add ? "" : s.state.rows[index].scene, video, probe);
          row["video"] = video;
        }
        return add ? store.AddRow(version, row) : store.EditRow(version, id, row);
      });
    });
    http.Post(R"(/api/rows/(\d{1,12})/detach)", [this](const httplib::Request& req, httplib::Response& res) {
      Respond(req, res, [this, &req](const json& b) {
        const internal::DetachedVideo d = internal::DetachRowVideo(store, VersionOf(b), std::stoll(req.matches[1].str()),
                                                                   report_mutex);
        return ordered_json{{"video", d.video}, {"moved_to", d.moved_to}, {"state", StateJson(d.after)}};
      });
    });
    http.Put(kVideoUploadPattern, [this](const httplib::Request& req, httplib::Response& res,
                                       const httplib::ContentReader& reader) {
      Upload(req, res, reader, internal::kVideoUploadFolder, internal::VideoUpload(), options.max_upload_bytes,
             [](const std::string& staged, const std::string& name) {
               const VideoProbe probe = ProbeVideo(staged, name);
               return ordered_json{{"width", probe.width}, {"height", probe.height}, {"fps", probe.fps},
                                   {"frames", probe.frames}};
             });
    });
    http.Put(kViewUploadPattern, [this](const httplib::Request& req, httplib::Response& res,
                                      const httplib::ContentReader& reader) {
      Upload(req, res, reader, internal::kViewUploadFolder, internal::ImageUpload(), options.max_view_upload_bytes,
             [](const std::string& staged, const std::string& name) {
               const internal::ImageSize size = internal::ProbeImage(staged, name);
               return ordered_json{{"width", size.width}, {"height", size.height}};
             });
    });
  }

  // An upload into `directory` (internal/video_upload.hpp): `probe` checks the staged file (throwing
  // InputError to refuse it) and describes it; the answer is {path, ...the description}.
  void Upload(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader,
              const std::string& directory, const internal::UploadKind& kind, std::size_t max_bytes,
              const std::function<ordered_json(const std::string& path, const std::string& name)>& probe) {
    const auto close = [] { internal::BoundedHttpServer::CloseAfterResponse(); };
    const UploadSlot slot(uploads, options.max_concurrent_uploads);
    if (!slot.held()) {
      SendError(res, 503, std::to_string(options.max_concurrent_uploads) +
                              " uploads are being received already (the most at once): send this file when one of "
                              "them has ended");
      res.set_header("Connection", "close");  // its body is not read
      return close();
    }
    try {
      const ContainedDirectory* folder = store.folder();
      if (!folder) throw InputError("experiment", "does not exist yet: create it first");
      ClaimFolder();
      const std::string name = req.matches[1].str();
      ordered_json described;
      const std::string path = internal::ReceiveUpload(
          *folder, directory, name, kind, req.get_header_value<std::uint64_t>("Content-Length"), max_bytes,
          [&](const std::function<bool(const char*, std::size_t)>& sink) { return reader(sink); },
          [&](const std::string& staged) { described = probe(staged, name); });
      ordered_json answer{{"path", path}};
      answer.update(described);
      SendJson(res, 200, answer);
    } catch (const InputError& e) {
      if (internal::BoundedHttpServer::RequestStalled())
        SendError(res, 408, req.matches[1].str() + ": no byte arrived for " + Seconds(options.upload_idle_timeout) +
                                ": the upload stalled and was closed; nothing was kept", "upload");
      else if (internal::BoundedHttpServer::RequestTimedOut())
        SendError(res, 408, req.matches[1].str() + ": not received within the upload's deadline; nothing was kept",
                  "upload");
      else
        SendError(res, 422, e.what(), e.quantity());
      res.set_header("Connection", "close");  // the rest of the body, if any, is not read
      close();
    } catch (const std::exception& e) {
      SendError(res, 500, e.what());  // the server's disk or folder (full, failing), not the request
      res.set_header("Connection", "close");
      close();
    }
  }

  // The fit report of the files as they are, written into a private staging folder inside the
  // experiment and then moved, file by file, into EXP/report/ (a real folder, never a link).
  void WriteReport(httplib::Response& res) {
    const ContainedDirectory* folder = store.folder();
    if (!folder) throw InputError("experiment", "does not exist yet: create it first");
    using Kind = ContainedDirectory::Kind;
    for (const char* name : {"experiment.json", "measurements.csv"})
      if (const Kind kind = folder->KindOf(name); kind != Kind::kFile && kind != Kind::kAbsent) {
        SendError(res, 403, std::string("refused: ") + name + " is not a regular file of the experiment folder");
        return;
      }
    if (const Kind kind = folder->KindOf("report"); kind != Kind::kAbsent && kind != Kind::kDirectory) {
      SendError(res, 403, "refused: " + (fs::path(store.directory()) / "report").string() +
                              " is not a folder (a symbolic link or a file): the report is written only inside "
                              "the experiment folder");
      return;
    }
    ExperimentFolderOptions analysis_options;
    analysis_options.analysis.mc_trials = options.report_mc_trials;
    Experiment experiment = LoadExperiment(store.directory());
    const std::string report_folder = (fs::path(store.directory()) / "report").string();
    CheckReportOutputs(experiment, report_folder, "report");  // 422 before any work: never over an input
    ClaimFolder();
    ContainedDirectory staging = folder->MakeStagingDirectory(internal::kReportStagingPrefix);
    std::vector<std::string> names;
    ExperimentFolderAnalysis written;
    try {
      // Written into a staging folder, then moved into EXP/report.
      written = WriteExperimentReport(std::move(experiment), {staging.path(), report_folder, "report"}, analysis_options);
      const ContainedDirectory target = folder->Subdirectory("report", true);
      for (const std::string& name : staging.RegularFiles()) {
        if (!ValidReportName(name)) continue;
        staging.MoveFile(name, target, name);
        names.push_back(name);
      }
    } catch (...) {
      ContainedDirectory::RemoveStaging(*folder, std::move(staging));
      throw;
    }
    ContainedDirectory::RemoveStaging(*folder, std::move(staging));
    ordered_json files = ordered_json::array();
    for (const auto& n : names) files.push_back(n);
    SendJson(res, 200, {{"url", "/report/report.html"}, {"files", files}, {"trial_errors", written.trial_errors},
                        {"notes", written.notes}});
  }
};

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) { impl_->Routes(); }

Server::~Server() { Stop(); }

int Server::Bind() {
  if (impl_->options.port == 0) {
    impl_->port = impl_->http.bind_to_any_port(impl_->options.host);
    if (impl_->port <= 0) throw EnvironmentError("--host " + impl_->options.host + ": cannot listen on this address");
  } else {
    if (!impl_->http.bind_to_port(impl_->options.host, impl_->options.port))
      throw EnvironmentError("--port " + std::to_string(impl_->options.port) + ": cannot listen on " +
                             impl_->options.host + ":" + std::to_string(impl_->options.port) +
                             " (the port is in use, or the address is not this computer's; --port 0 picks a free one)");
    impl_->port = impl_->options.port;
  }
  impl_->http.WidenBacklog();
  return impl_->port;
}

void Server::Run() {
  // A Stop() after this test closes the socket, and listen_after_bind() then returns at once.
  if (!impl_->stopped) impl_->http.listen_after_bind();
}

void Server::Stop() {
  if (!impl_) return;
  impl_->stopped = true;
  impl_->http.StopListening();
}

ExperimentStore& Server::store() { return impl_->store; }

std::size_t Server::largest_request_bytes() const { return impl_->http.LargestRequestBytes(); }

}  // namespace uphill
