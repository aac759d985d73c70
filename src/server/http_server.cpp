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
// Last: it includes <httplib.h>, which includes <resolv.h>, whose `_res` macro breaks Eigen.
#include "internal/bounded_http_server.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

constexpr std::size_t kMaxReportFileBytes = 64u << 20;

constexpr const char* kPagePolicy =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; connect-src 'self'; "
    "form-action 'none'; frame-ancestors 'none'; base-uri 'none'";
// Report files are documents, not the app: no script at all, their own inline styles, sandboxed.
constexpr const char* kReportPolicy =
    "default-src 'none'; img-src 'self' data:; style-src 'unsafe-inline'; frame-ancestors 'none'; sandbox";

void SecurityHeaders(httplib::Response& res) {
  if (!res.has_header("Content-Security-Policy")) res.set_header("Content-Security-Policy", kPagePolicy);
  if (!res.has_header("Cache-Control")) res.set_header("Cache-Control", "no-store");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("X-Frame-Options", "DENY");
}

void SendJson(httplib::Response& res, int status, const ordered_json& body) {
  res.status = status;
  // Text that is not UTF-8 never gets this far (422 naming the field); `replace` keeps an answer
  // an answer even if some did.
  res.set_content(body.dump(-1, ' ', false, ordered_json::error_handler_t::replace), "application/json; charset=utf-8");
}

void SendError(httplib::Response& res, int status, const std::string& message, const std::string& field = "") {
  ordered_json body = {{"error", message}};
  if (!field.empty()) body["field"] = field;
  SendJson(res, status, body);
}

// A request body as JSON. Nesting is bounded: no request of the page is deeper than 4.
// Marks a byte that is not UTF-8 while the field holding it is looked for: U+FDD0, a
// noncharacter that no keyboard produces.
constexpr std::string_view kBadByteMark = "\xEF\xB7\x90";

// The path of the first key or string value that contains the mark, as the API names fields
// ("row.note", "experiment.body.a"), or "" if none.
std::string MarkedField(const json& j, const std::string& path) {
  const auto marked = [](const std::string& s) { return s.find(kBadByteMark) != std::string::npos; };
  if (j.is_string()) return marked(j.get_ref<const std::string&>()) ? path : "";
  if (j.is_object())
    for (const auto& [key, value] : j.items()) {
      const std::string inner = path.empty() ? key : path + "." + key;
      if (marked(key)) return inner;
      if (std::string found = MarkedField(value, inner); !found.empty()) return found;
    }
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      if (std::string found = MarkedField(j[i], path + "[" + std::to_string(i) + "]"); !found.empty()) return found;
  return "";
}

const json::parser_callback_t kDepthLimit = [](int depth, json::parse_event_t, json&) {
  if (depth > 16) throw InputError("request", "JSON nested too deeply");
  return true;
};

// Text that is not UTF-8 (a Latin-1 paste, a broken client) is refused naming the field that
// holds it, which JSON's own parser cannot do: the bad bytes are marked, the marked document is
// parsed, and the field with the mark is named.
[[noreturn]] void RefuseNotUtf8(const std::string& body) {
  std::string marked;
  std::string_view rest = body;
  for (std::size_t bad; (bad = InvalidUtf8At(rest)) != std::string_view::npos;) {
    marked.append(rest.substr(0, bad)).append(kBadByteMark);
    rest.remove_prefix(bad + 1);
  }
  marked.append(rest);
  const json j = json::parse(marked, nullptr, false);
  std::string field = j.is_discarded() ? "" : MarkedField(j, "");
  if (field.empty()) field = "request";
  // The key itself may be the bad text: name it with the mark shown as U+FFFD.
  for (std::size_t at; (at = field.find(kBadByteMark)) != std::string::npos;) field.replace(at, kBadByteMark.size(), "\xEF\xBF\xBD");
  throw InputError(field.substr(0, 96), "is not valid UTF-8 text (the page sends UTF-8: retype or paste it again)");
}

json ParseBody(const httplib::Request& req) {
  if (req.body.empty()) return json::object();
  if (InvalidUtf8At(req.body) != std::string_view::npos) RefuseNotUtf8(req.body);
  return json::parse(req.body, kDepthLimit);
}

std::int64_t VersionOf(const json& body) {
  if (!body.is_object() || !body.contains("version") || !body.at("version").is_number_integer())
    throw std::invalid_argument("version: missing (the version of the state the change was made against)");
  return body.at("version").get<std::int64_t>();
}

// The routes whose body is not JSON: uploads, streamed to disk (internal/video_upload.hpp). The
// pre-routing handler sends every PUT under these prefixes through the upload's checks (its name
// first), so a name the route's pattern does not match is refused by the name's rule.
constexpr const char* kVideoUploadPrefix = "/api/videos/";
constexpr const char* kViewUploadPrefix = "/api/views/";
constexpr const char* kVideoUploadPattern = R"(/api/videos/([^/]{1,120}))";
constexpr const char* kViewUploadPattern = R"(/api/views/([^/]{1,120}))";

struct UploadRoute {
  const internal::UploadKind* kind = nullptr;
  std::size_t limit = 0;
  std::string name;  // as decoded from the path
};

// The upload a request is, or nullopt when it is none.
std::optional<UploadRoute> UploadRouteOf(const httplib::Request& req, const ServerOptions& options) {
  if (req.method != "PUT") return std::nullopt;
  for (const auto& [prefix, kind, limit] :
       {std::tuple{kVideoUploadPrefix, &internal::VideoUpload(), options.max_upload_bytes},
        std::tuple{kViewUploadPrefix, &internal::ImageUpload(), options.max_view_upload_bytes}})
    if (req.path.rfind(prefix, 0) == 0) return UploadRoute{kind, limit, req.path.substr(std::strlen(prefix))};
  return std::nullopt;
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

// "application/json", optionally with "; charset=utf-8": the only body the API reads. Anything
// else, "application/jsonx" or "text/plain" included, is refused (a cross-site form cannot send
// this type without a CORS preflight, which this server never grants).
bool IsJsonContentType(const std::string& value) {
  std::string v;
  for (char c : value)
    if (c != ' ' && c != '\t') v += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return v == "application/json" || v == "application/json;charset=utf-8";
}

// Headers whose meaning is lost when they are sent twice (which Host decides the origin check,
// which length the body has): a request with two of them is refused.
constexpr const char* kSingleHeaders[] = {"Host", "Origin", "Content-Type", "Content-Length", "Transfer-Encoding"};

std::string ContentType(const std::string& name) {
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".json") return "application/json; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  return "text/plain; charset=utf-8";  // .md, .gp, .dat, anything else: shown, never run
}

internal::ConnectionLimits Limits(const ServerOptions& options) {
  internal::ConnectionLimits limits;
  limits.request_budget_bytes = options.max_request_bytes + 32 * 1024;  // the body and its headers
  limits.request_deadline = options.request_deadline;
  limits.idle_timeout = options.idle_timeout;
  limits.max_connections = options.max_connections;
  return limits;
}

// Refuses a request before its body is read, and closes the connection (the unread body must not
// be taken for the next request).
httplib::Server::HandlerResponse Refuse(httplib::Response& res, int status, const std::string& message,
                                        const std::string& field = "") {
  SendError(res, status, message, field);
  SecurityHeaders(res);
  res.set_header("Connection", "close");
  internal::BoundedHttpServer::CloseAfterResponse();
  return httplib::Server::HandlerResponse::Handled;
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

  bool AllowedHost(const httplib::Request& req) const {
    if (options.host != "127.0.0.1" && options.host != "localhost" && options.host != "::1") return true;
    const std::string host = req.get_header_value("Host");
    std::string p = std::to_string(port);
    p.insert(p.begin(), ':');  // not ":" + ...: GCC 12 gives a false -Wrestrict there
    if (host.size() <= p.size() || host.compare(host.size() - p.size(), p.size(), p) != 0) return false;
    const std::string name = host.substr(0, host.size() - p.size());
    return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
  }

  void Routes() {
    // Uploads may be large; every other request is held to max_request_bytes before its body is
    // read (pre-routing handler) and by its connection's byte budget.
    http.set_payload_max_length(
        std::max({options.max_request_bytes, options.max_upload_bytes, options.max_view_upload_bytes}));

    // Every request, before its body is read: the headers that decide how it is read and whom it
    // comes from must be there once, the body must have a length, and it must come from here.
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      for (const char* name : kSingleHeaders)
        if (req.get_header_value_count(name) > 1)
          return Refuse(res, 400, std::string("the ") + name + " header is given more than once: refused");
      if (req.has_header("Transfer-Encoding"))
        return Refuse(res, 411, "send the body with a Content-Length (Transfer-Encoding is refused)");
      if (!AllowedHost(req)) return Refuse(res, 403, "Host header must be this server's loopback address");
      if (req.method != "GET" && req.method != "HEAD") {
        const std::string origin = req.get_header_value("Origin");
        if (!origin.empty() && origin != "http://" + req.get_header_value("Host"))
          return Refuse(res, 403, "cross-origin change refused");
        if (const std::optional<UploadRoute> upload = UploadRouteOf(req, options)) {
          try {
            internal::CheckUploadName(upload->name, *upload->kind);
          } catch (const InputError& e) {
            return Refuse(res, 422, e.what(), e.quantity());
          }
          if (req.get_header_value("Content-Type") != "application/octet-stream")
            return Refuse(res, 415, "an upload must be sent as application/octet-stream");
          const std::size_t length = req.get_header_value<std::uint64_t>("Content-Length");
          if (length > upload->limit)
            return Refuse(res, 413, "the file is larger than the upload limit (" + std::to_string(upload->limit >> 20) + " MiB)");
          internal::BoundedHttpServer::AllowLargeRequest(length + 32 * 1024, options.upload_deadline,
                                                         options.upload_idle_timeout);
          return httplib::Server::HandlerResponse::Unhandled;
        }
        if (!IsJsonContentType(req.get_header_value("Content-Type")))
          return Refuse(res, 415, "changes must be sent as application/json");
      }
      if (req.get_header_value<std::uint64_t>("Content-Length") > options.max_request_bytes)
        return Refuse(res, 413, "request too large (at most " + std::to_string(options.max_request_bytes / 1024) + " KiB)");
      return httplib::Server::HandlerResponse::Unhandled;
    });
    http.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) { SecurityHeaders(res); });
    http.set_error_handler([this](const httplib::Request&, httplib::Response& res) {
      if (internal::BoundedHttpServer::RequestOverBudget()) {
        res.status = 413;
        res.body.clear();
      } else if (internal::BoundedHttpServer::RequestTimedOut() && res.body.empty()) {
        res.status = 408;  // an upload that stalled has said so itself
      }
      if (res.body.empty()) {
        const std::string message =
            res.status == 413 ? "request too large (at most " + std::to_string(options.max_request_bytes / 1024) + " KiB)"
            : res.status == 408 ? "request not received in time"
            : res.status == 404 ? "not found"
            : res.status == 400 ? "malformed request"
                                : "error";
        SendError(res, res.status, message);
      }
      // A request that was refused before its body was read, or could not be read: the rest of
      // the connection cannot be trusted to start a new request.
      if (res.status == 400 || res.status == 408 || res.status == 411 || res.status == 413 || res.status == 414) {
        res.set_header("Connection", "close");
        internal::BoundedHttpServer::CloseAfterResponse();
      }
      SecurityHeaders(res);
    });
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
      std::string message = "internal error";
      try {
        if (ep) std::rethrow_exception(ep);
      } catch (const std::exception& e) {
        message += std::string(": ") + e.what();
      } catch (...) {
      }
      SendError(res, 500, message);
      SecurityHeaders(res);
    });

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
      try {
        const json body = ParseBody(req);
        const StoreSnapshot s = store.Get();
        const json row_json = body.value("row", json::object());
        Row row;
        try {
          row = ValidateRow(row_json, s.state);
        } catch (const InputError& e) {
          // A draft that is not yet complete is still checked as far as it goes.
          ordered_json out = {{"complete", false}, {"error", e.what()}, {"field", e.quantity()}};
          SendJson(res, 200, out);
          return;
        }
        row.id = row_json.is_object() && row_json.contains("id") && row_json.at("id").is_number_integer()
                     ? row_json.at("id").get<std::int64_t>()
                     : 0;
        ordered_json out = {{"complete", true}};
        const ordered_json check = ToJson(CheckRow(s.state, row), s.state.unit);
        for (const auto& [k, v] : check.items()) out[k] = v;
        SendJson(res, 200, out);
      } catch (const InputError& e) {
        SendError(res, 422, e.what(), e.quantity());
      } catch (const json::exception& e) {
        SendError(res, 400, std::string("malformed JSON: ") + e.what());
      } catch (const std::invalid_argument& e) {
        SendError(res, 400, e.what());
      }
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
          CheckSceneFits(s, add ? "" : s.state.rows[index].scene, video, probe);
          row["video"] = video;
        }
        return add ? store.AddRow(version, row) : store.EditRow(version, id, row);
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

  // A scene file that does not fit the video's size is refused when the video is attached (the
  // track would be wrong everywhere): the row's scene, or the experiment's only scene.
  static void CheckSceneFits(const StoreSnapshot& s, std::string scene, const std::string& video,
                             const VideoProbe& probe) {
    const ordered_json& meta = s.state.metadata;
    if (!meta.is_object() || !meta.contains("scenes")) return;
    if (scene.empty() && meta.at("scenes").size() == 1) scene = meta.at("scenes").begin().key();
    if (scene.empty() || !meta.at("scenes").contains(scene)) return;
    const std::string path = meta.at("scenes").at(scene).get<std::string>();
    const auto it = s.state.files.find(path);
    if (it == s.state.files.end()) return;
    const SceneCalibration calibration = ParseSceneFile(path, it->second);
    if (calibration.camera.width != probe.width || calibration.camera.height != probe.height)
      throw InputError("video", video + " is " + std::to_string(probe.width) + "×" + std::to_string(probe.height) +
                                    " px but the scene file " + path + " (scene \"" + scene + "\") is for " +
                                    std::to_string(calibration.camera.width) + "×" +
                                    std::to_string(calibration.camera.height) +
                                    " px: calibrate a scene for this video's camera setting");
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
    const ExperimentFolderAnalysis folder_analysis = AnalyseExperimentFolder(store.directory(), analysis_options);
    const ExperimentAnalysis& analysis = folder_analysis.analysis;
    CheckReportOutputs(*folder_analysis.experiment, (fs::path(store.directory()) / "report").string(), "report");  // 422: never over an input
    ClaimFolder();
    ContainedDirectory staging = folder->MakeStagingDirectory(internal::kReportStagingPrefix);
    std::vector<std::string> names;
    try {
      WriteFitReport(analysis, staging.path());
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
    SendJson(res, 200, {{"url", "/report/report.html"}, {"files", files}});
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
