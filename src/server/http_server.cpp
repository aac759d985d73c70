#include "server/http_server.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "io/experiment.hpp"
#include "model/input_error.hpp"
#include "report/analysis.hpp"
#include "report/fit_document.hpp"
#include "internal/page_assets.hpp"
#include "server/row_check.hpp"
// Last: it includes <resolv.h>, whose `_res` macro breaks Eigen (a parameter of that name).
#include <httplib.h>

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

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
  res.set_content(body.dump(), "application/json; charset=utf-8");
}

void SendError(httplib::Response& res, int status, const std::string& message, const std::string& field = "") {
  ordered_json body = {{"error", message}};
  if (!field.empty()) body["field"] = field;
  SendJson(res, status, body);
}

// A request body as JSON. Nesting is bounded: no request of the page is deeper than 4.
json ParseBody(const httplib::Request& req) {
  if (req.body.empty()) return json::object();
  const json::parser_callback_t depth_limit = [](int depth, json::parse_event_t, json&) {
    if (depth > 16) throw InputError("request", "JSON nested too deeply");
    return true;
  };
  return json::parse(req.body, depth_limit);
}

std::int64_t VersionOf(const json& body) {
  if (!body.is_object() || !body.contains("version") || !body.at("version").is_number_integer())
    throw std::invalid_argument("version: missing (the version of the state the change was made against)");
  return body.at("version").get<std::int64_t>();
}

bool ValidReportName(const std::string& name) {
  static const std::regex ok("[A-Za-z0-9][A-Za-z0-9._-]{0,127}");
  return std::regex_match(name, ok) && name.find("..") == std::string::npos;
}

std::string ContentType(const std::string& name) {
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".json") return "application/json; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  return "text/plain; charset=utf-8";  // .md, .gp, .dat, anything else: shown, never run
}

}  // namespace

struct Server::Impl {
  ServerOptions options;
  ExperimentStore store;
  httplib::Server http;
  int port = 0;
  std::mutex report_mutex;

  explicit Impl(ServerOptions o) : options(std::move(o)), store(options.directory) {}

  std::string ReportDirectory() const { return (fs::path(options.directory) / "report").string(); }

  ordered_json StateJson(const StoreSnapshot& s) const {
    ordered_json j;
    j["version"] = s.version;
    j["can_undo"] = s.can_undo;
    j["directory"] = fs::absolute(options.directory).string();
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
    const bool report = fs::exists(fs::path(ReportDirectory()) / "report.html");
    j["report"] = {{"exists", report}, {"url", report ? json("/report/report.html") : json(nullptr)}};
    return j;
  }

  // Runs a change: maps every outcome to its status code; success returns the new state.
  template <class Change>
  void Mutate(const httplib::Request& req, httplib::Response& res, Change change) {
    try {
      const json body = ParseBody(req);
      SendJson(res, 200, StateJson(change(body)));
    } catch (const VersionConflict& e) {
      SendJson(res, 409, {{"error", e.what()}, {"state", StateJson(e.current())}});
    } catch (const InputError& e) {
      SendError(res, 422, e.what(), e.quantity());
    } catch (const json::exception& e) {
      SendError(res, 400, std::string("malformed JSON: ") + e.what());
    } catch (const std::invalid_argument& e) {
      SendError(res, 400, e.what());
    } catch (const std::exception& e) {
      SendError(res, 500, e.what());
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
    http.set_payload_max_length(options.max_request_bytes);
    http.set_read_timeout(10, 0);
    http.set_write_timeout(10, 0);
    http.set_keep_alive_timeout(5);

    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      if (!AllowedHost(req)) {
        SendError(res, 403, "Host header must be this server's loopback address");
        SecurityHeaders(res);
        return httplib::Server::HandlerResponse::Handled;
      }
      if (req.method != "GET" && req.method != "HEAD") {
        const std::string origin = req.get_header_value("Origin");
        if (!origin.empty() && origin != "http://" + req.get_header_value("Host")) {
          SendError(res, 403, "cross-origin change refused");
          SecurityHeaders(res);
          return httplib::Server::HandlerResponse::Handled;
        }
        if (req.get_header_value("Content-Type").rfind("application/json", 0) != 0) {
          SendError(res, 415, "changes must be sent as application/json");
          SecurityHeaders(res);
          return httplib::Server::HandlerResponse::Handled;
        }
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
    http.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) { SecurityHeaders(res); });
    http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
      if (res.body.empty()) {
        const std::string message = res.status == 413 ? "request too large" : res.status == 404 ? "not found" : "error";
        SendError(res, res.status, message);
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
      }
    });
    http.Post("/api/report", [this](const httplib::Request&, httplib::Response& res) {
      std::lock_guard lock(report_mutex);  // one report at a time; the store stays free meanwhile
      try {
        const Experiment experiment = LoadExperiment(options.directory);
        AnalysisOptions analysis_options;
        analysis_options.mc_trials = options.report_mc_trials;
        const ExperimentAnalysis analysis = AnalyseExperiment(experiment, analysis_options);
        WriteFitReport(analysis, ReportDirectory());
        ordered_json files = ordered_json::array();
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(ReportDirectory()))
          if (entry.is_regular_file() && ValidReportName(entry.path().filename().string()))
            names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        for (const auto& n : names) files.push_back(n);
        SendJson(res, 200, {{"url", "/report/report.html"}, {"files", files}});
      } catch (const InputError& e) {
        SendError(res, 422, e.what(), e.quantity());
      } catch (const std::exception& e) {
        SendError(res, 500, e.what());
      }
    });
    http.Get("/report/(.*)", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string name = req.matches[1].str();
      if (!ValidReportName(name)) {
        SendError(res, 403, "refused: report files are served by plain name only");
        return;
      }
      const std::string path = (fs::path(ReportDirectory()) / name).string();
      struct stat st {};
      if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {  // no symlinks out of the folder
        SendError(res, 404, "no such report file: " + name);
        return;
      }
      std::ifstream in(path, std::ios::binary);
      std::stringstream content;
      content << in.rdbuf();
      res.set_header("Content-Security-Policy", kReportPolicy);
      res.set_content(content.str(), ContentType(name));
    });
  }
};

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) { impl_->Routes(); }

Server::~Server() { Stop(); }

int Server::Bind() {
  if (impl_->options.port == 0) {
    impl_->port = impl_->http.bind_to_any_port(impl_->options.host);
    if (impl_->port <= 0) throw std::runtime_error("cannot listen on " + impl_->options.host);
  } else {
    if (!impl_->http.bind_to_port(impl_->options.host, impl_->options.port))
      throw std::runtime_error("cannot listen on " + impl_->options.host + ":" + std::to_string(impl_->options.port) +
                               " (in use? try --port 0 for any free port)");
    impl_->port = impl_->options.port;
  }
  return impl_->port;
}

void Server::Run() { impl_->http.listen_after_bind(); }

void Server::Stop() {
  if (impl_) impl_->http.stop();
}

ExperimentStore& Server::store() { return impl_->store; }

}  // namespace uphill
