#include "bounded_http_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace uphill::internal {
namespace {

using Clock = std::chrono::steady_clock;

// Polls `sock` for `events` until `until`, in slices, so that a stopping server is noticed.
// Returns true when ready.
bool WaitFor(int sock, short events, Clock::time_point until, const std::atomic<socket_t>* listening = nullptr) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
    if (left <= 0) return false;
    if (listening && *listening == INVALID_SOCKET) return false;
    pollfd p{sock, events, 0};
    const int rc = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 200)));
    if (rc > 0) return true;
    if (rc < 0 && errno != EINTR) return false;
  }
}

void IpAndPort(const sockaddr_storage& address, std::string& ip, int& port) {
  char buf[INET6_ADDRSTRLEN] = "";
  if (address.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&address);
    ::inet_ntop(AF_INET, &a->sin_addr, buf, sizeof buf);
    port = ntohs(a->sin_port);
  } else if (address.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&address);
    ::inet_ntop(AF_INET6, &a->sin6_addr, buf, sizeof buf);
    port = ntohs(a->sin6_port);
  }
  ip = buf;
}

// One connection's stream: buffered reads within the current request's byte budget and
// deadline, writes within the write timeout.
class BoundedStream : public httplib::Stream {
 public:
  BoundedStream(int sock, const ConnectionLimits& limits) : sock_(sock), limits_(limits) {}

  // A new request starts: a fresh budget (bytes already buffered count against it) and deadline.
  void StartRequest() {
    used_ = end_ - begin_;
    budget_ = limits_.request_budget_bytes;
    deadline_ = Clock::now() + limits_.request_deadline;
    idle_ = std::chrono::milliseconds(0);
    over_budget_ = timed_out_ = stalled_ = close_ = false;
  }
  bool has_buffered() const { return begin_ < end_; }
  bool over_budget() const { return over_budget_; }
  bool timed_out() const { return timed_out_; }
  bool stalled() const { return stalled_; }
  std::size_t used() const { return used_ - (end_ - begin_); }  // bytes of this request read
  bool close_requested() const { return close_ || over_budget_ || timed_out_; }
  void RequestClose() { close_ = true; }
  void AllowLarge(std::size_t bytes, std::chrono::milliseconds deadline, std::chrono::milliseconds idle) {
    budget_ = std::max(budget_, bytes);
    deadline_ = std::max(deadline_, Clock::now() + deadline);
    idle_ = idle;
  }

  bool is_readable() const override { return has_buffered() || WaitFor(sock_, POLLIN, deadline_); }
  bool is_writable() const override {
    return WaitFor(sock_, POLLOUT, Clock::now() + limits_.write_timeout);
  }

  ssize_t read(char* ptr, size_t size) override {
    if (!has_buffered()) {
      if (used_ >= budget_) {
        over_budget_ = true;
        return -1;
      }
      const Clock::time_point idle_until = idle_.count() > 0 ? Clock::now() + idle_ : deadline_;
      if (!WaitFor(sock_, POLLIN, std::min(deadline_, idle_until))) {
        timed_out_ = true;
        stalled_ = idle_until < deadline_;
        return -1;
      }
      const std::size_t room = std::min(sizeof buffer_, budget_ - used_);
      ssize_t n;
      do {
        n = ::recv(sock_, buffer_, room, 0);
      } while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      begin_ = 0;
      end_ = static_cast<std::size_t>(n);
      used_ += end_;
    }
    const std::size_t n = std::min(size, end_ - begin_);
    std::memcpy(ptr, buffer_ + begin_, n);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n;
    do {
      n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&address), &length) == 0) IpAndPort(address, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&address), &length) == 0) IpAndPort(address, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  int sock_;
  const ConnectionLimits& limits_;
  char buffer_[4096];
  std::size_t begin_ = 0, end_ = 0;
  std::size_t used_ = 0;
  std::size_t budget_ = 0;
  Clock::time_point deadline_;
  std::chrono::milliseconds idle_{0};  // 0: no limit between bytes (only the deadline)
  bool over_budget_ = false, timed_out_ = false, stalled_ = false, close_ = false;
};

thread_local BoundedStream* current_stream = nullptr;

// A thread pool that starts a thread whenever every thread is busy, up to a maximum; jobs beyond
// that wait for a free thread.
class GrowingThreadPool : public httplib::TaskQueue {
 public:
  explicit GrowingThreadPool(std::size_t max_threads) : max_threads_(std::max<std::size_t>(1, max_threads)) {}
  ~GrowingThreadPool() override { shutdown(); }

  void enqueue(std::function<void()> job) override {
    std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(job));
    if (jobs_.size() > idle_ && threads_.size() < max_threads_) threads_.emplace_back([this] { Work(); });
    ready_.notify_one();
  }

  void shutdown() override {
    {
      std::lock_guard lock(mutex_);
      if (stopping_ && threads_.empty()) return;
      stopping_ = true;
    }
    ready_.notify_all();
    for (std::thread& t : threads_)
      if (t.joinable()) t.join();
    threads_.clear();
  }

 private:
  void Work() {
    for (;;) {
      std::function<void()> job;
      {
        std::unique_lock lock(mutex_);
        ++idle_;
        ready_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
        --idle_;
        if (jobs_.empty()) return;  // stopping, and nothing left to do
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      job();
    }
  }

  const std::size_t max_threads_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  std::size_t idle_ = 0;
  bool stopping_ = false;
};

}  // namespace

BoundedHttpServer::BoundedHttpServer(ConnectionLimits limits) : limits_(limits) {
  new_task_queue = [max = limits_.max_connections] { return new GrowingThreadPool(max); };
  // SO_REUSEADDR only (cpp-httplib's default adds SO_REUSEPORT, which lets a second server
  // bind the same port and take half of the clients).
  set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
}

void BoundedHttpServer::WidenBacklog(int backlog) {
  // listen() again on a listening socket changes its backlog (Linux).
  if (svr_sock_ != INVALID_SOCKET) ::listen(svr_sock_, backlog);
}

void BoundedHttpServer::StopListening() {
  // httplib's accept loop runs while svr_sock_ is valid and treats a failed accept on an
  // invalidated socket as a stop; shutdown wakes a poll or accept already waiting on it.
  const socket_t sock = svr_sock_.exchange(INVALID_SOCKET);
  if (sock == INVALID_SOCKET) return;
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
}

void BoundedHttpServer::CloseAfterResponse() {
  if (current_stream) current_stream->RequestClose();
}

void BoundedHttpServer::AllowLargeRequest(std::size_t bytes, std::chrono::milliseconds deadline,
                                          std::chrono::milliseconds idle) {
  if (current_stream) current_stream->AllowLarge(bytes, deadline, idle);
}

bool BoundedHttpServer::RequestOverBudget() { return current_stream && current_stream->over_budget(); }
bool BoundedHttpServer::RequestTimedOut() { return current_stream && current_stream->timed_out(); }
bool BoundedHttpServer::RequestStalled() { return current_stream && current_stream->stalled(); }

bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  BoundedStream stream(sock, limits_);
  current_stream = &stream;
  bool ok = false;
  for (std::size_t served = 0; served < limits_.max_requests_per_connection; ++served) {
    if (svr_sock_ == INVALID_SOCKET) break;
    if (!stream.has_buffered() && !WaitFor(sock, POLLIN, Clock::now() + limits_.idle_timeout, &svr_sock_)) break;
    stream.StartRequest();
    bool connection_closed = false;
    const bool last = served + 1 == limits_.max_requests_per_connection;
    ok = process_request(stream, last, connection_closed, nullptr);
    for (std::size_t seen = largest_request_; stream.used() > seen;)
      if (largest_request_.compare_exchange_weak(seen, stream.used())) break;
    if (!ok || connection_closed || stream.close_requested()) break;
  }
  current_stream = nullptr;
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ok;
}

}  // namespace uphill::internal
