// The HTTP API of `uphill serve` (src/server/): an in-process server on a free loopback port,
// driven with httplib::Client; a crash test that SIGKILLs the real program mid-burst and
// restarts it; and a concurrency test with two writers.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "io/experiment.hpp"
#include "server/experiment_store.hpp"
#include "server/row_check.hpp"
// Last: it includes <httplib.h>, which includes <resolv.h>, whose `_res` macro breaks Eigen.
#include "server_test_support.hpp"

namespace uphill::testing {
namespace {

using namespace uphill::testing;
using uphill::testing::Row;  // the sample row, not the state's Row

class ServerTest : public ServerFixture {
 protected:
  static std::vector<std::string> Codes(const json& check) { return FlagCodes(check); }
  static bool Has(const std::vector<std::string>& codes, const std::string& code) {
    return std::find(codes.begin(), codes.end(), code) != codes.end();
  }
};

TEST_F(ServerTest, ServesTheEmbeddedPageWithAStrictPolicy) {
  auto page = client_->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<script src=\"/app.js\">"), std::string::npos);
  const std::string csp = page->get_header_value("Content-Security-Policy");
  EXPECT_NE(csp.find("default-src 'none'"), std::string::npos);
  EXPECT_NE(csp.find("script-src 'self'"), std::string::npos);
  EXPECT_EQ(csp.find("unsafe-inline"), std::string::npos);
  auto js = client_->Get("/app.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_EQ(js->body.find("innerHTML"), std::string::npos);  // user text only via textContent
  EXPECT_EQ(js->body.find("http://cdn"), std::string::npos);
}

TEST_F(ServerTest, CreatesAnExperimentAndWritesFilesThatLoad) {
  json s = State();
  EXPECT_FALSE(s["exists"]);
  EXPECT_EQ(s["version"], 0);
  s = Create();
  EXPECT_TRUE(s["exists"]);
  EXPECT_EQ(s["version"], 1);
  EXPECT_EQ(s["columns"], json({"L", "D", "Y"}));
  EXPECT_TRUE(fs::exists(dir_ / "experiment.json"));
  EXPECT_TRUE(fs::exists(dir_ / "journal.jsonl"));
  Add(Row("t1", 150, 392));
  s = Add(Row("t2, with \"quotes\"", 200, 292));
  ASSERT_EQ(s["rows"].size(), 2u);
  const Experiment e = LoadExperiment(dir_.string());
  ASSERT_EQ(e.rows.size(), 2u);
  EXPECT_TRUE(e.rows[0].error.empty()) << e.rows[0].error;
  EXPECT_EQ(e.rows[1].trial, "t2, with \"quotes\"");
  EXPECT_NEAR(e.rows[0].Y.value, 0.392, 1e-12);
  EXPECT_NEAR(e.rows[0].Y.u, 0.0005, 1e-12);
  EXPECT_EQ(e.title, "Series 2 <script>alert(1)</script>");  // stored as text; the page never parses it
}

TEST_F(ServerTest, ComputesTheModelAndTheFit) {
  Create();
  Add(Row("t1", 150, 392));
  Add(Row("t2", 200, 292));
  const json s = Add(Row("t3", 250, 232));
  const json& c = s["rows"][0]["check"];
  // tanθ = 300/1165, tan(α/2) = 150/2330.
  EXPECT_NEAR(c["theta_deg"].get<double>(), std::atan(300.0 / 1165) * 180 / M_PI, 1e-9);
  EXPECT_NEAR(c["alpha_deg"].get<double>(), 2 * std::atan(150.0 / 2330) * 180 / M_PI, 1e-9);
  EXPECT_GT(c["x"].get<double>(), 300);
  EXPECT_LT(c["x"].get<double>(), 392);
  EXPECT_GT(c["u_x"].get<double>(), 0);
  EXPECT_NEAR(c["residual"].get<double>(), 392 - c["x"].get<double>(), 1e-9);
  EXPECT_TRUE(c["flags"].empty()) << c.dump();
  EXPECT_EQ(s["fit"]["n"], 3);
  EXPECT_TRUE(s["fit"].contains("slope")) << s["fit"].dump();
}

TEST_F(ServerTest, FlagsMistakes) {
  Create();
  Add(Row("t1", 150, 392));
  Add(Row("t2", 200, 292));
  const auto check = [&](const json& row) {
    auto [status, body] = Send("POST", "/api/check", {{"row", row}});
    EXPECT_EQ(status, 200) << body.dump();
    EXPECT_TRUE(body["complete"]) << body.dump();
    return Codes(body);
  };
  EXPECT_TRUE(check(Row("t3", 150, 393)).empty());
  EXPECT_TRUE(Has(check(Row("t3", 150, 900)), "y_far"));
  EXPECT_TRUE(Has(check(Row("t3", 150, 392)), "duplicate_row"));
  EXPECT_TRUE(Has(check(Row("t1", 150, 393)), "duplicate_trial"));
  EXPECT_TRUE(Has(check(Row("t3", 175.0 / 25.4, 392)), "unit_mixup"));  // D typed in inches
  EXPECT_TRUE(Has(check(Row("t3", 150, 392 / 25.4)), "unit_mixup"));   // Y typed in inches
  json far = Row("t3", 150, 392);
  far["L"] = "9000";
  EXPECT_TRUE(Has(check(far), "implausible"));
  EXPECT_TRUE(Has(check(Row("t3", 45, 1300)), "x_beyond_crossbar"));  // the paper's D = 45 mm
  // An incomplete draft is answered, not refused.
  auto [status, body] = Send("POST", "/api/check", {{"row", {{"trial", "t4"}, {"L", "1165"}}}});
  EXPECT_EQ(status, 200);
  EXPECT_FALSE(body["complete"]);
  EXPECT_EQ(body["field"], "row.D");
}

TEST_F(ServerTest, EditsDeletesAndUndoes) {
  Create();
  Add(Row("t1", 150, 392));
  json s = Add(Row("t2", 200, 292));
  const std::int64_t id1 = s["rows"][0]["id"];
  auto [st1, edited] = Send("PUT", "/api/rows/" + std::to_string(id1), {{"version", s["version"]}, {"row", Row("t1", 150, 393)}});
  ASSERT_EQ(st1, 200) << edited.dump();
  EXPECT_EQ(edited["rows"][0]["Y"], "393");
  auto [st2, deleted] = Send("DELETE", "/api/rows/" + std::to_string(id1), {{"version", edited["version"]}});
  ASSERT_EQ(st2, 200);
  EXPECT_EQ(deleted["rows"].size(), 1u);
  EXPECT_TRUE(deleted["can_undo"]);
  auto [st3, undone] = Send("POST", "/api/undo", {{"version", deleted["version"]}});
  ASSERT_EQ(st3, 200);
  ASSERT_EQ(undone["rows"].size(), 2u);
  EXPECT_EQ(undone["rows"][0]["id"], id1);  // back in its place, with its id
  EXPECT_EQ(undone["rows"][0]["Y"], "393");
  auto [st4, undone2] = Send("POST", "/api/undo", {{"version", undone["version"]}});
  ASSERT_EQ(st4, 200);
  EXPECT_EQ(undone2["rows"][0]["Y"], "392");  // the edit undone too
  // The history survives a restart.
  Stop();
  Start();
  json after = State();
  EXPECT_EQ(after["version"], undone2["version"]);
  EXPECT_EQ(after["rows"], undone2["rows"]);
  EXPECT_TRUE(after["can_undo"]);  // the add of t2 can still be undone
  EXPECT_EQ(LoadExperiment(dir_.string()).rows.size(), 2u);
}

// Issue 11: making D a constant of the apparatus silently dropped the measured D column from
// measurements.csv (the fit then used the constant for every row). Truth: the rows as entered,
// read back from the files by the analysis' own reader (LoadExperiment).
TEST_F(ServerTest, MakingAMeasuredQuantityAConstantIsRefused) {
  Create();
  Add(Row("t1", 150, 392));
  const json s = Add(Row("t2", 200, 292));
  json constant_d = ExperimentMetadata();
  constant_d["apparatus"]["D"] = "175 mm";
  auto [status, body] = Send("PUT", "/api/experiment", {{"version", s["version"]}, {"experiment", constant_d}, {"unit", "mm"}});
  EXPECT_EQ(status, 422) << body.dump();
  EXPECT_EQ(body["field"], "apparatus.D") << body.dump();
  EXPECT_NE(body["error"].get<std::string>().find("2 row(s) have a measured D"), std::string::npos) << body.dump();
  json angles = ExperimentMetadata();
  angles["apparatus"] = {{"theta", "1 deg"}, {"alpha", "60 deg"}};
  EXPECT_EQ(Send("PUT", "/api/experiment", {{"version", s["version"]}, {"experiment", angles}, {"unit", "mm"}}).first, 422);
  EXPECT_EQ(State()["columns"], json({"L", "D", "Y"}));
  const Experiment e = LoadExperiment(dir_.string());
  ASSERT_EQ(e.rows.size(), 2u);
  EXPECT_TRUE(e.rows[1].error.empty()) << e.rows[1].error;
  ASSERT_TRUE(e.rows[1].configuration.has_value());
  EXPECT_NEAR(e.rows[1].configuration->D.value, 0.200, 1e-12);
}

TEST_F(ServerTest, StaleVersionIsAConflictWithTheCurrentState) {
  Create();
  const json s = Add(Row("t1", 150, 392));
  const std::int64_t stale = s["version"].get<std::int64_t>() - 1;
  auto [status, body] = Send("POST", "/api/rows", {{"version", stale}, {"row", Row("t2", 200, 292)}});
  EXPECT_EQ(status, 409);
  EXPECT_NE(body["error"].get<std::string>().find("changed meanwhile"), std::string::npos);
  EXPECT_EQ(body["state"]["version"], s["version"]);
  EXPECT_EQ(body["state"]["rows"].size(), 1u);
  auto [st2, b2] = Send("PUT", "/api/rows/" + std::to_string(s["rows"][0]["id"].get<int>()),
                        {{"version", stale}, {"row", Row("t1", 150, 999)}});
  EXPECT_EQ(st2, 409);
  EXPECT_EQ(State()["rows"][0]["Y"], "392");
}

TEST_F(ServerTest, RefusesBadRequests) {
  Create();
  const json v = State()["version"];
  // Too large.
  json big = Row("t1");
  big["note"] = std::string(100 * 1024, 'x');
  EXPECT_EQ(Send("POST", "/api/rows", {{"version", v}, {"row", big}}).first, 413);
  // Bad content: 422 naming the field; malformed JSON and a missing version: 400.
  json bad = Row("t1");
  bad["D"] = "12 mm";
  auto [st, body] = Send("POST", "/api/rows", {{"version", v}, {"row", bad}});
  EXPECT_EQ(st, 422);
  EXPECT_EQ(body["field"], "row.D");
  json control = Row("t1");
  control["trial"] = "a\nb";
  EXPECT_EQ(Send("POST", "/api/rows", {{"version", v}, {"row", control}}).first, 422);
  EXPECT_EQ(Send("POST", "/api/rows", {{"row", Row("t1")}}).first, 400);
  auto malformed = client_->Post("/api/rows", "{\"version\":", kJson);
  ASSERT_TRUE(malformed);
  EXPECT_EQ(malformed->status, 400);
  auto deep = client_->Post("/api/rows", std::string(5000, '[') + std::string(5000, ']'), kJson);
  ASSERT_TRUE(deep);
  EXPECT_EQ(deep->status, 422);
  // Not JSON: refused before any handler (a cross-site form cannot send application/json).
  auto form = client_->Post("/api/rows", "version=1", "application/x-www-form-urlencoded");
  ASSERT_TRUE(form);
  EXPECT_EQ(form->status, 415);
  // Another origin, another Host.
  httplib::Headers origin = {{"Origin", "http://evil.example"}};
  auto cross = client_->Post("/api/rows", origin, json({{"version", v}, {"row", Row("t1")}}).dump(), kJson);
  ASSERT_TRUE(cross);
  EXPECT_EQ(cross->status, 403);
  httplib::Headers host = {{"Host", "evil.example"}};
  auto rebinding = client_->Get("/api/state", host);
  ASSERT_TRUE(rebinding);
  EXPECT_EQ(rebinding->status, 403);
  EXPECT_EQ(State()["rows"].size(), 0u);
}

TEST_F(ServerTest, ServesReportFilesByNameOnly) {
  CreateWithThreeRows();
  fs::create_directories(dir_ / "report");
  std::ofstream(dir_ / "report" / "note.md") << "# hello\n";
  auto ok = client_->Get("/report/note.md");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  EXPECT_EQ(ok->body, "# hello\n");
  EXPECT_NE(ok->get_header_value("Content-Security-Policy").find("sandbox"), std::string::npos);
  for (const char* path : {"/report/../experiment.json", "/report/..%2fexperiment.json", "/report/%2e%2e/journal.jsonl",
                           "/report/.hidden", "/report/a/../../experiment.json", "/report/..", "/../experiment.json"}) {
    auto r = client_->Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_NE(r->status, 200) << path;
    EXPECT_EQ(r->body.find("uphill-experiment"), std::string::npos) << path;
  }
  fs::create_symlink(dir_ / "experiment.json", dir_ / "report" / "link.json");
  auto link = client_->Get("/report/link.json");
  ASSERT_TRUE(link);
  EXPECT_EQ(link->status, 403);  // never followed (server_security_test.cpp: links at any level)
}

TEST_F(ServerTest, WritesTheFitReport) {
  CreateWithThreeRows();
  auto [status, body] = Send("POST", "/api/report", json::object());
  ASSERT_EQ(status, 200) << body.dump();
  EXPECT_EQ(body["url"], "/report/report.html");
  auto html = client_->Get("/report/report.html");
  ASSERT_TRUE(html);
  EXPECT_EQ(html->status, 200);
  EXPECT_TRUE(State()["report"]["exists"]);
}

TEST(ExperimentStoreTest, RecoversFromACrashBetweenJournalAndFiles) {
  const fs::path dir = TempDir("store-recovery");
  std::string csv_before;
  {
    ExperimentStore store(dir.string());
    store.SetMetadata(0, ExperimentMetadata(), "mm");
    store.AddRow(1, Row("t1", 150, 392));
    std::stringstream s;
    s << std::ifstream(dir / "measurements.csv").rdbuf();
    csv_before = s.str();
    store.AddRow(2, Row("t2", 200, 292));
  }
  // As if the server died after the journal entry of t2 but before the files were replaced.
  { std::ofstream(dir / "measurements.csv", std::ios::binary) << csv_before; }
  // And while appending a third entry (never acknowledged): a torn line.
  { std::ofstream(dir / "journal.jsonl", std::ios::app) << "{\"version\":4,\"op\":{\"ty"; }
  {
    ExperimentStore store(dir.string());
    const StoreSnapshot s = store.Get();
    EXPECT_EQ(s.version, 3);
    ASSERT_EQ(s.state.rows.size(), 2u);
    EXPECT_EQ(LoadExperiment(dir.string()).rows.size(), 2u);  // files rewritten
    store.AddRow(3, Row("t3", 250, 232));                          // the journal continues cleanly
  }
  {
    ExperimentStore store(dir.string());
    EXPECT_EQ(store.Get().state.rows.size(), 3u);
  }
  // Files edited by hand while the server was off: they win.
  {
    std::ofstream(dir / "measurements.csv", std::ios::binary) << "trial,series,L_mm,D_mm,Y_mm,note\nh1,,1165,150,421,by hand\n";
    ExperimentStore store(dir.string());
    ASSERT_EQ(store.Get().state.rows.size(), 1u);
    EXPECT_EQ(store.Get().state.rows[0].trial, "h1");
    const std::int64_t v = store.Get().version;
    store.AddRow(v, Row("t9", 200, 330));
  }
  {
    ExperimentStore store(dir.string());
    ASSERT_EQ(store.Get().state.rows.size(), 2u);
    EXPECT_EQ(store.Get().state.rows[0].trial, "h1");
  }
  fs::remove_all(dir);
}

TEST(ExperimentStoreTest, OpensAHandMadeExperimentWithoutWriting) {
  const fs::path dir = TempDir("sample");
  fs::copy(fs::path(UPHILL_SOURCE_DIR) / "data" / "series2-fixed-L", dir, fs::copy_options::recursive);
  {
    ExperimentStore store(dir.string());
    EXPECT_EQ(store.Get().state.rows.size(), LoadExperiment(dir.string()).rows.size());
    EXPECT_FALSE(fs::exists(dir / "journal.jsonl"));
    const json checks = CheckAll(store.Get().state);  // declared in row_check.hpp
    EXPECT_EQ(checks["fit"]["n"], store.Get().state.rows.size());
  }
  fs::remove_all(dir);
}

TEST_F(ServerTest, TwoWritersLoseNothing) {
  Create();
  constexpr int kPerWriter = 15;
  std::atomic<int> acknowledged{0};
  const auto writer = [&](const std::string& prefix) {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(10);
    for (int i = 0; i < kPerWriter; ++i) {
      const json row = Row(prefix + std::to_string(i), 110 + i * 9 + (prefix == "b" ? 4 : 0), 400);
      // Retry on 409 against the version the conflict reports (bounded).
      auto state = c.Get("/api/state");
      ASSERT_TRUE(state);
      std::int64_t version = json::parse(state->body)["version"];
      for (int attempt = 0; attempt < 200; ++attempt) {
        auto r = c.Post("/api/rows", json({{"version", version}, {"row", row}}).dump(), kJson);
        ASSERT_TRUE(r);
        if (r->status == 200) {
          ++acknowledged;
          break;
        }
        ASSERT_EQ(r->status, 409) << r->body;
        version = json::parse(r->body)["state"]["version"];
      }
    }
  };
  std::thread a(writer, "a"), b(writer, "b");
  a.join();
  b.join();
  EXPECT_EQ(acknowledged.load(), 2 * kPerWriter);
  const json s = State();
  std::set<std::string> trials;
  for (const json& r : s["rows"]) trials.insert(r["trial"]);
  EXPECT_EQ(trials.size(), 2u * kPerWriter);
  EXPECT_EQ(LoadExperiment(dir_.string()).rows.size(), 2u * kPerWriter);
}

// The real program, killed with SIGKILL in the middle of a burst of writes, then restarted.
class ServeProcess {
 public:
  ServeProcess(const fs::path& dir) {
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      ::close(out[0]);
      ::close(out[1]);
      ::execl(UPHILL_PROGRAM, UPHILL_PROGRAM, "serve", dir.c_str(), "--port", "0", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(out[1]);
    // "uphill serve: http://127.0.0.1:PORT/ ..." is the first line.
    std::string line;
    char c;
    while (line.size() < 4096 && ::read(out[0], &c, 1) == 1 && c != '\n') line += c;
    ::close(out[0]);
    const auto colon = line.find("127.0.0.1:");
    if (colon == std::string::npos) throw std::runtime_error("no address in: " + line);
    port_ = std::stoi(line.substr(colon + 10));
  }
  ~ServeProcess() { Kill(SIGKILL); }
  void Kill(int signal) {
    if (pid_ <= 0) return;
    ::kill(pid_, signal);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  int port() const { return port_; }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
};

TEST(ServeProcessTest, KillNineLosesNoAcknowledgedRow) {
  signal(SIGPIPE, SIG_IGN);  // writing to the killed server must fail, not kill the test
  const fs::path dir = TempDir("kill9");
  std::set<std::string> acknowledged;
  {
    ServeProcess serve(dir);
    httplib::Client c("127.0.0.1", serve.port());
    c.set_read_timeout(5);
    auto r = c.Put("/api/experiment", json({{"version", 0}, {"experiment", ExperimentMetadata()}, {"unit", "mm"}}).dump(), kJson);
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
    std::int64_t version = json::parse(r->body)["version"];
    // Killed in the middle of the burst: once 20 writes have been acknowledged (an event, not a
    // time), while the writer goes on sending.
    std::atomic<bool> killed{false};
    std::atomic<int> acknowledged_count{0};
    std::thread killer([&] {
      WaitUntil([&] { return acknowledged_count >= 20; });
      serve.Kill(SIGKILL);
      killed = true;
    });
    for (int i = 0; i < 100000 && !killed; ++i) {
      const std::string trial = std::string("k").append(std::to_string(i));  // not "k" + …: GCC 12 -Wrestrict
      auto w = c.Post("/api/rows", json({{"version", version}, {"row", Row(trial, 110 + (i % 100), 400 + i % 7)}}).dump(), kJson);
      if (!w) {
        if (killed) break;
        continue;
      }
      ASSERT_EQ(w->status, 200) << w->body;
      acknowledged.insert(trial);
      ++acknowledged_count;
      version = json::parse(w->body)["version"];
    }
    killer.join();
  }
  ASSERT_GT(acknowledged.size(), 0u);
  ServeProcess again(dir);
  httplib::Client c("127.0.0.1", again.port());
  auto r = c.Get("/api/state");
  ASSERT_TRUE(r);
  const json s = json::parse(r->body);
  std::set<std::string> present;
  for (const json& row : s["rows"]) present.insert(row["trial"]);
  for (const std::string& t : acknowledged) EXPECT_TRUE(present.count(t)) << "lost acknowledged row " << t;
  EXPECT_LE(present.size(), acknowledged.size() + 1);  // at most the one in flight
  const Experiment e = LoadExperiment(dir.string());
  EXPECT_EQ(e.rows.size(), present.size());
  again.Kill(SIGTERM);
  fs::remove_all(dir);
}

// ---- stopping, and starting after a killed server ----

// Runs `server` on a thread and says whether Run() returned within a minute. A Run() that never
// returns cannot be joined: the test program then stops at once with the failure, instead of
// hanging until ctest's timeout.
void ExpectRunReturns(Server& server, const std::string& what) {
  auto returned = std::make_shared<std::promise<void>>();
  std::future<void> done = returned->get_future();
  std::thread([&server, returned] {
    server.Run();
    returned->set_value();
  }).detach();
  if (done.wait_for(std::chrono::minutes(1)) != std::future_status::ready) {
    ADD_FAILURE() << what << ": Run() did not return: the stop was lost";
    std::_Exit(1);
  }
}

// httplib's own stop() does nothing until the accept loop has marked itself running, so a Stop()
// that came before Run() was lost and Run() listened for ever (ServerFixture's join hung). The
// truth: Run() returns, and nobody listens on the port afterwards.
TEST(ServerStopTest, StopBeforeRunOrBindMakesRunReturn) {
  const fs::path dir = TempDir("stop-before-run");
  ServerOptions options;
  options.directory = dir.string();
  options.port = 0;
  {
    Server server(options);
    const int port = server.Bind();
    server.Stop();
    ExpectRunReturns(server, "Stop() after Bind()");
    const int sock = ConnectLoopback(port);
    EXPECT_LT(sock, 0) << "still listening on port " << port;
    if (sock >= 0) ::close(sock);
    server.Stop();  // twice: harmless
  }
  {
    Server server(options);
    server.Stop();
    server.Bind();
    ExpectRunReturns(server, "Stop() before Bind()");
  }
  fs::remove_all(dir);
}

// The fixture's own order: start (a thread that calls Run()) and stop at once, many times; each
// Stop() joins. Then the server still works.
TEST_F(ServerTest, StopsRightAfterStart) {
  for (int i = 0; i < 50; ++i) {
    Stop();
    Start();
  }
  EXPECT_EQ(State()["version"], 0);
}

// What a folder holds, every entry by its path: a file's bytes, a link's target, or "folder".
std::map<std::string, std::string> FolderBytes(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = fs::relative(it->path(), root).generic_string();
    if (it->is_symlink()) {
      out[name] = "link to " + fs::read_symlink(it->path()).string();
    } else if (it->is_directory()) {
      out[name] = "folder";
    } else {
      std::ifstream in(it->path(), std::ios::binary);
      out[name] = std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
  }
  return out;
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// A server killed mid-upload or mid-report leaves its staging folder behind (`.upload-` or
// `.report-staging-` and 16 hex digits, where it stages). The next server to start alone on the
// folder removes exactly those; while another server holds the folder, nothing is removed (its
// staging may be live). Truth: the folder's own bytes, read before the server started.
TEST(ServerStartTest, RemovesOnlyItsOwnStaleStagingAndOnlyWhenAlone) {
  const fs::path dir = TempDir("stale-staging");
  const fs::path outside = TempDir("stale-staging-outside");
  {
    ExperimentStore store(dir.string());
    store.SetMetadata(0, ExperimentMetadata(), "mm");
    store.AddRow(1, Row("t1"));
  }
  const std::string clip(5000, '\x7f');
  WriteBytes(dir / "videos" / "clip.mp4", clip);
  // Not the server's staging, whatever they look like: all kept.
  WriteBytes(dir / "videos" / ".upload-0123" / "upload", "short suffix");
  WriteBytes(dir / "videos" / ".upload-0123456789ABCDEF" / "upload", "upper-case hex");
  WriteBytes(dir / "videos" / ".upload-1111111111111111", "a file, not a folder");
  WriteBytes(dir / "videos" / ".upload-2222222222222222" / "inner" / "upload", "holds a folder");
  WriteBytes(dir / ".upload-3333333333333333" / "upload", "uploads are not staged here");
  WriteBytes(dir / "notes" / ".report-staging-4444444444444444" / "report.html", "reports are not staged here");
  WriteBytes(dir / ".uphill-cache" / "video" / ".staging-5555555555555555" / "track.csv", "the tracker cache's");
  WriteBytes(outside / "keep.txt", "outside the folder");
  fs::create_directory_symlink(outside, dir / ".report-staging-6666666666666666");
  fs::create_directories(dir / "calibration" / "views");  // where chessboard views are uploaded
  const std::map<std::string, std::string> before = FolderBytes(dir);
  // The server's own, stale.
  const std::vector<fs::path> stale = {dir / "videos" / ".upload-0123456789abcdef",
                                       dir / "calibration" / "views" / ".upload-fedcba9876543210",
                                       dir / ".report-staging-00000000000000aa"};
  const auto make_stale = [&] {
    WriteBytes(stale[0] / "upload", clip.substr(0, 1234));
    WriteBytes(stale[1] / "upload", "half a PNG");
    WriteBytes(stale[2] / "report.html", "<html>");
    WriteBytes(stale[2] / "fit.json", "{}");
  };
  make_stale();
  // Another server holds the folder: nothing is removed.
  ServerOptions options;
  options.directory = dir.string();
  options.port = 0;
  {
    Server first(options);
    for (const fs::path& p : stale) EXPECT_FALSE(fs::exists(p)) << p << " (the first server is alone)";
    make_stale();
    Server second(options);
    for (const fs::path& p : stale) EXPECT_TRUE(fs::exists(p)) << p << " removed while the first server holds the folder";
  }
  // Alone again: its own stale staging is gone, the rest untouched byte for byte.
  {
    Server alone(options);
    for (const fs::path& p : stale) EXPECT_FALSE(fs::exists(p)) << p;
    EXPECT_EQ(FolderBytes(dir), before);
    EXPECT_EQ(FolderBytes(outside), (std::map<std::string, std::string>{{"keep.txt", "outside the folder"}}));
  }
  fs::remove_all(dir);
  fs::remove_all(outside);
}

}  // namespace
}  // namespace uphill::testing
