// The server's gate: what every request must pass before its body is read, and how a request
// that fails is answered. Before routing: the headers that decide how a request is read and whom
// it comes from (Host, Origin, Content-Type, Content-Length, Transfer-Encoding) given once; a
// body with a length; a Host that is this server's loopback address when it listens on one; no
// cross-origin change; an upload (PUT /api/videos/NAME, /api/views/NAME) checked by its name,
// type and size and then given its own byte budget and deadlines; any other change sent as JSON
// and within max_request_bytes. After routing: the security headers. Errors and exceptions:
// one JSON error, the connection closed where the rest of it cannot be trusted. Status codes:
// docs/serve.md.
#pragma once

#include "server/http_server.hpp"
// Last: it includes <httplib.h>, whose <resolv.h> defines a `_res` macro that breaks Eigen.
#include "bounded_http_server.hpp"

namespace uphill::internal {

// Installs the gate on `http`. `port` is read at each request (the port is known once bound).
void GuardRequests(BoundedHttpServer& http, const ServerOptions& options, const int& port);

}  // namespace uphill::internal
