#include "request_gate.hpp"

#include <algorithm>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <tuple>

#include "model/input_error.hpp"
#include "video_upload.hpp"
// Last: it includes <httplib.h>, whose <resolv.h> defines a `_res` macro that breaks Eigen.
#include "http_replies.hpp"

namespace uphill::internal {
namespace {

constexpr const char* kVideoUploadPrefix = "/api/videos/";
constexpr const char* kViewUploadPrefix = "/api/views/";

// Headers whose meaning is lost when they are sent twice (which Host decides the origin check,
// which length the body has): a request with two of them is refused.
constexpr const char* kSingleHeaders[] = {"Host", "Origin", "Content-Type", "Content-Length", "Transfer-Encoding"};

struct UploadRoute {
  const UploadKind* kind = nullptr;
  std::size_t limit = 0;
  std::string name;  // as decoded from the path
};

// The upload a request is, or nullopt when it is none.
std::optional<UploadRoute> UploadRouteOf(const httplib::Request& req, const ServerOptions& options) {
  if (req.method != "PUT") return std::nullopt;
  for (const auto& [prefix, kind, limit] :
       {std::tuple{kVideoUploadPrefix, &VideoUpload(), options.max_upload_bytes},
        std::tuple{kViewUploadPrefix, &ImageUpload(), options.max_view_upload_bytes}})
    if (req.path.rfind(prefix, 0) == 0) return UploadRoute{kind, limit, req.path.substr(std::strlen(prefix))};
  return std::nullopt;
}

bool AllowedHost(const httplib::Request& req, const ServerOptions& options, int port) {
  if (options.host != "127.0.0.1" && options.host != "localhost" && options.host != "::1") return true;
  const std::string host = req.get_header_value("Host");
  std::string p = std::to_string(port);
  p.insert(p.begin(), ':');  // not ":" + ...: GCC 12 gives a false -Wrestrict there
  if (host.size() <= p.size() || host.compare(host.size() - p.size(), p.size(), p) != 0) return false;
  const std::string name = host.substr(0, host.size() - p.size());
  return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
}

}  // namespace

void GuardRequests(BoundedHttpServer& http, const ServerOptions& options, const int& port) {
  // Uploads may be large; every other request is held to max_request_bytes before its body is
  // read (pre-routing handler) and by its connection's byte budget.
  http.set_payload_max_length(
      std::max({options.max_request_bytes, options.max_upload_bytes, options.max_view_upload_bytes}));

  // Every request, before its body is read: the headers that decide how it is read and whom it
  // comes from must be there once, the body must have a length, and it must come from here.
  http.set_pre_routing_handler([&options, &port](const httplib::Request& req, httplib::Response& res) {
    for (const char* name : kSingleHeaders)
      if (req.get_header_value_count(name) > 1)
        return Refuse(res, 400, std::string("the ") + name + " header is given more than once: refused");
    if (req.has_header("Transfer-Encoding"))
      return Refuse(res, 411, "send the body with a Content-Length (Transfer-Encoding is refused)");
    if (!AllowedHost(req, options, port)) return Refuse(res, 403, "Host header must be this server's loopback address");
    if (req.method != "GET" && req.method != "HEAD") {
      const std::string origin = req.get_header_value("Origin");
      if (!origin.empty() && origin != "http://" + req.get_header_value("Host"))
        return Refuse(res, 403, "cross-origin change refused");
      if (const std::optional<UploadRoute> upload = UploadRouteOf(req, options)) {
        try {
          CheckUploadName(upload->name, *upload->kind);
        } catch (const InputError& e) {
          return Refuse(res, 422, e.what(), e.quantity());
        }
        if (req.get_header_value("Content-Type") != "application/octet-stream")
          return Refuse(res, 415, "an upload must be sent as application/octet-stream");
        const std::size_t length = req.get_header_value<std::uint64_t>("Content-Length");
        if (length > upload->limit)
          return Refuse(res, 413, "the file is larger than the upload limit (" + std::to_string(upload->limit >> 20) + " MiB)");
        BoundedHttpServer::AllowLargeRequest(length + 32 * 1024, options.upload_deadline,
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
  http.set_error_handler([&options](const httplib::Request&, httplib::Response& res) {
    if (BoundedHttpServer::RequestOverBudget()) {
      res.status = 413;
      res.body.clear();
    } else if (BoundedHttpServer::RequestTimedOut() && res.body.empty()) {
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
      BoundedHttpServer::CloseAfterResponse();
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
}

}  // namespace uphill::internal
