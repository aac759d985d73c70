// Shared by the server's test programs (server_test.cpp, server_security_test.cpp): an
// in-process server on a free loopback port, a sample experiment and rows, and a raw-socket
// client for requests httplib::Client would not send (duplicate headers, endless lines).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "server/http_server.hpp"
// Last: <httplib.h> includes <resolv.h>, whose `_res` macro breaks Eigen.
#include <httplib.h>

namespace uphill::testing {

namespace fs = std::filesystem;
using nlohmann::json;

inline constexpr const char* kJson = "application/json";

// A fresh (removed) temporary path for one test.
fs::path TempDir(const std::string& name);

// The seed paper's series 2 as an experiment: spheroid 15.875 × 25.4 mm, H = 300 mm constant.
json ExperimentMetadata();

// A plausible row of series 2 (L = 1165 mm, D varied). X is 389.8 mm at D = 150 mm, 289.7 at
// 200, 229.1 at 250 (the fall-off 5-8 mm further): Y a little beyond X.
json Row(const std::string& trial, double D = 150, double Y = 392);

// The codes of a check's flags ({"flags":[{"code"…}]}, src/server/row_check.hpp), in order.
std::vector<std::string> FlagCodes(const json& check);

// A TCP connection to 127.0.0.1:port, its descriptor (the caller closes it), or -1.
int ConnectLoopback(int port);

// Sends raw bytes to 127.0.0.1:port and returns what comes back until the server closes the
// connection or `timeout` passes ("" if nothing came back).
std::string RawExchange(int port, const std::string& request, std::chrono::milliseconds timeout);

// The status code of a raw HTTP answer ("HTTP/1.1 413 …" → 413), 0 if none.
int StatusOf(const std::string& answer);

// Waits for an event: polls `condition` until it holds (returns true at once then) or until the
// generous `limit` has passed (false). The limit only ends a test that would otherwise hang; it
// is never what the test measures.
bool WaitUntil(const std::function<bool()>& condition, std::chrono::seconds limit = std::chrono::seconds(60));

// Opens a connection that sends the head of an upload PUT `path` declaring `declared` bytes and
// then `sent` bytes of its body, and stalls. Returns the socket (the caller closes it), or -1.
int StartStalledUpload(int port, const std::string& path, std::size_t declared, std::size_t sent);

// Whether the server has closed `sock`, without waiting: what it sent meanwhile is appended to
// `answer` (whole once this returns true).
bool ClosedByServer(int sock, std::string& answer);

class ServerFixture : public ::testing::Test {
 protected:
  void SetUp() override { Start(); }
  void TearDown() override;
  virtual void Configure(ServerOptions& /*options*/) {}
  void Start();
  void Stop();
  json State();
  // Sends a change; returns {status, body} (status 0 when nothing came back).
  std::pair<int, json> Send(const std::string& method, const std::string& path, const json& body);
  json Create();
  json Add(const json& row);
  // The experiment and three rows of series 2 (D = 150, 200, 250 mm): enough for every fit.
  json CreateWithThreeRows();

  fs::path dir_ = TempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::unique_ptr<Server> server_;
  std::thread thread_;
  std::unique_ptr<httplib::Client> client_;
  int port_ = 0;
};

}  // namespace uphill::testing
