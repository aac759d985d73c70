// How the server answers and reads a request, shared by its routes (http_server.cpp and the
// route files beside it): the security headers of every answer, JSON answers and errors
// ({"error": message, "field": the field named}), the JSON body of a request (UTF-8 checked,
// the bad field named; nesting bounded), and the refusal of a request before its body is read.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

// Last among includes of the users too: <httplib.h> includes <resolv.h>, whose `_res` macro
// breaks Eigen.
#include "bounded_http_server.hpp"

namespace uphill::internal {

// The page's Content-Security-Policy (unless the answer set its own), no caching, no sniffing,
// no referrer, no framing.
void SecurityHeaders(httplib::Response& res);

void SendJson(httplib::Response& res, int status, const nlohmann::ordered_json& body);
void SendError(httplib::Response& res, int status, const std::string& message, const std::string& field = "");

// A request body as JSON ({} when empty). Throws InputError naming the field whose text is not
// UTF-8, or "request" when nested deeper than 16; nlohmann::json::exception when malformed.
nlohmann::json ParseBody(const httplib::Request& req);

// The body's "version": the state the change was made against. std::invalid_argument when missing.
std::int64_t VersionOf(const nlohmann::json& body);

// "application/json", optionally with "; charset=utf-8": the only body the API reads. Anything
// else, "application/jsonx" or "text/plain" included, is refused (a cross-site form cannot send
// this type without a CORS preflight, which this server never grants).
bool IsJsonContentType(const std::string& value);

// The Content-Type of a report file by its extension; text for anything unknown (shown, never run).
std::string ContentType(const std::string& name);

// Refuses a request before its body is read, and closes the connection (the unread body must not
// be taken for the next request).
httplib::Server::HandlerResponse Refuse(httplib::Response& res, int status, const std::string& message,
                                        const std::string& field = "");

}  // namespace uphill::internal
