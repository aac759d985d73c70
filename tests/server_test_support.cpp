#include "server_test_support.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <thread>

namespace uphill::testing {

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("uphill-server-test-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(dir);
  return dir;
}

json ExperimentMetadata() {
  return {{"title", "Series 2 <script>alert(1)</script>"},
          {"operator", "A. Technician"},
          {"body", {{"type", "spheroid"}, {"a", "15.875 mm"}, {"b", "25.4 mm"}}},
          {"apparatus", {{"H", "300 mm"}, {"L_convention", "horizontal"}}},
          {"uncertainties", {{"L", "1 mm"}, {"H", "0.5 mm"}, {"D", "0.2 mm"}, {"Y", "0.5 mm"}}}};
}

std::vector<std::string> FlagCodes(const json& check) {
  std::vector<std::string> codes;
  for (const json& f : check["flags"]) codes.push_back(f["code"]);
  return codes;
}

json Row(const std::string& trial, double D, double Y) {
  char d[32], y[32];
  std::snprintf(d, sizeof d, "%g", D);
  std::snprintf(y, sizeof y, "%g", Y);
  return {{"trial", trial}, {"series", "s2"}, {"L", "1165"}, {"D", d}, {"Y", y}, {"note", "ok"}};
}

int ConnectLoopback(int port) {
  const int sock = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (sock < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
  if (::connect(sock, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(sock);
    return -1;
  }
  return sock;
}

bool WaitUntil(const std::function<bool()>& condition, std::chrono::seconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  for (;;) {
    if (condition()) return true;
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // a poll's pace, not a wait for the event
  }
}

int StartStalledUpload(int port, const std::string& path, std::size_t declared, std::size_t sent) {
  const int sock = ConnectLoopback(port);
  if (sock < 0) return -1;
  const std::string head = "PUT " + path + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                           "\r\nContent-Type: application/octet-stream\r\nContent-Length: " + std::to_string(declared) +
                           "\r\n\r\n" + std::string(sent, 'x');
  if (::send(sock, head.data(), head.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(head.size())) {
    ::close(sock);
    return -1;
  }
  return sock;
}

bool ClosedByServer(int sock, std::string& answer) {
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(sock, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) {
      answer.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    return n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR);
  }
}

std::string RawExchange(int port, const std::string& request, std::chrono::milliseconds timeout) {
  const int sock = ConnectLoopback(port);
  if (sock < 0) return "";
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string answer;
  std::size_t sent = 0;
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{sock, static_cast<short>(POLLIN | (sent < request.size() ? POLLOUT : 0)), 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    if (p.revents & POLLIN) {
      const ssize_t n = ::recv(sock, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      answer.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    if (p.revents & POLLOUT) {
      const ssize_t n = ::send(sock, request.data() + sent, std::min<std::size_t>(request.size() - sent, 65536), MSG_NOSIGNAL);
      if (n <= 0) {
        sent = request.size();  // the server stopped reading: only listen now
        continue;
      }
      sent += static_cast<std::size_t>(n);
    }
    if (p.revents & (POLLERR | POLLHUP)) break;
  }
  ::close(sock);
  return answer;
}

int StatusOf(const std::string& answer) {
  int status = 0;
  if (std::sscanf(answer.c_str(), "HTTP/1.%*d %d", &status) != 1) return 0;
  return status;
}

void ServerFixture::TearDown() {
  Stop();
  fs::remove_all(dir_);
}

void ServerFixture::Start() {
  ServerOptions options;
  options.directory = dir_.string();
  options.port = 0;
  options.report_mc_trials = 1000;
  Configure(options);
  server_ = std::make_unique<Server>(options);
  port_ = server_->Bind();
  thread_ = std::thread([this] { server_->Run(); });
  client_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
  client_->set_connection_timeout(5);
  client_->set_read_timeout(20);
}

void ServerFixture::Stop() {
  client_.reset();
  if (server_) server_->Stop();
  if (thread_.joinable()) thread_.join();
  server_.reset();
}

json ServerFixture::State() {
  auto r = client_->Get("/api/state");
  EXPECT_TRUE(r);
  if (!r) return json();
  EXPECT_EQ(r->status, 200);
  return json::parse(r->body);
}

std::pair<int, json> ServerFixture::Send(const std::string& method, const std::string& path, const json& body) {
  httplib::Result r = method == "POST"  ? client_->Post(path.c_str(), body.dump(), kJson)
                      : method == "PUT" ? client_->Put(path.c_str(), body.dump(), kJson)
                                        : client_->Delete(path.c_str(), body.dump(), kJson);
  if (!r) return {0, json()};
  json parsed;
  try {
    parsed = json::parse(r->body);
  } catch (...) {
  }
  return {r->status, parsed};
}

json ServerFixture::Create() {
  auto [status, body] =
      Send("PUT", "/api/experiment", {{"version", State()["version"]}, {"experiment", ExperimentMetadata()}, {"unit", "mm"}});
  EXPECT_EQ(status, 200) << body.dump();
  return body;
}

json ServerFixture::Add(const json& row) {
  auto [status, body] = Send("POST", "/api/rows", {{"version", State()["version"]}, {"row", row}});
  EXPECT_EQ(status, 200) << body.dump();
  return body;
}

json ServerFixture::CreateWithThreeRows() {
  Create();
  Add(Row("t1", 150, 392));
  Add(Row("t2", 200, 292));
  return Add(Row("t3", 250, 232));
}

}  // namespace uphill::testing
