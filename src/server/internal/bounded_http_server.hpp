// BoundedHttpServer: cpp-httplib's server with the limits a server on a shared machine needs and
// cpp-httplib 0.11 does not enforce itself. Private to src/server/.
//
// What cpp-httplib leaves open, and what this adds:
//   - It reads a request line or header line into memory until the newline, however long, and
//     a chunked body without any limit. Here every request has a byte budget (the body limit plus
//     room for the headers): a connection that sends more is answered 413 and closed, so no
//     request costs more memory than the budget.
//   - Its read timeout applies to each recv, so a client that trickles one byte every few
//     seconds keeps a thread forever. Here a request must arrive whole within `request_deadline`
//     (408 and closed otherwise), and an idle keep-alive connection is closed after
//     `idle_timeout`.
//   - Its thread pool has max(8, cores − 1) threads, each held by one connection while it is
//     open, so eight idle connections stall every other client. Here the pool grows on demand up
//     to `max_connections` threads, one per connection being served.
//   - It sets SO_REUSEPORT, so a second server on the same port starts and the kernel splits the
//     clients between them. Here only SO_REUSEADDR is set: a port in use is an error.
//   - It listens with a backlog of 5, so a burst of connections (a browser opens six) waits for
//     SYN retransmissions, a second or more. Here the backlog is widened after binding.
// A handler may also ask for the connection to be closed after its answer (CloseAfterResponse),
// e.g. when it refused a request whose body it did not read.
// Stopping: StopListening, which works even before listening has started (httplib's stop() does not).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>

// Last among includes of the users too: <httplib.h> includes <resolv.h>, whose `_res` macro
// breaks Eigen.
#include <httplib.h>

namespace uphill::internal {

struct ConnectionLimits {
  std::size_t request_budget_bytes = 96 * 1024;       // request line + headers + body
  std::chrono::milliseconds request_deadline{10000};  // from the first byte of a request to its end
  std::chrono::milliseconds idle_timeout{5000};       // between requests on one connection
  std::chrono::milliseconds write_timeout{10000};     // for each write of the answer
  std::size_t max_connections = 128;                  // served at once (threads)
  std::size_t max_requests_per_connection = 100;
};

class BoundedHttpServer : public httplib::Server {
 public:
  explicit BoundedHttpServer(ConnectionLimits limits);

  // After bind_to_port / bind_to_any_port: lets the kernel queue `backlog` connections.
  void WidenBacklog(int backlog = 256);

  // Closes the listening socket, whenever it is called: before listen_after_bind() (which then
  // returns at once), while it runs (it returns after the connections being served), or twice.
  // httplib's own stop() does nothing until listen_after_bind() has marked itself running, so
  // a stop that comes first is lost and the server then listens for ever.
  void StopListening();

  // For handlers (the thread serving the request): close the connection after this answer.
  static void CloseAfterResponse();
  // For the pre-routing handler of an upload: this request may hold `bytes` (its headers
  // included) and take until `deadline` from now, but no byte may take longer than `idle` to
  // come (a stalled upload is closed then, and its reader fails).
  static void AllowLargeRequest(std::size_t bytes, std::chrono::milliseconds deadline, std::chrono::milliseconds idle);
  // For the handlers: whether the current request ran out of its byte budget or deadline, or
  // stalled (no byte within the idle limit of AllowLargeRequest; it counts as timed out too).
  static bool RequestOverBudget();
  static bool RequestTimedOut();
  static bool RequestStalled();

  // The most bytes read for one request so far, on any connection.
  std::size_t LargestRequestBytes() const { return largest_request_; }

 private:
  bool process_and_close_socket(socket_t sock) override;

  ConnectionLimits limits_;
  std::atomic<std::size_t> largest_request_{0};
};

}  // namespace uphill::internal
