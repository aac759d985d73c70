// `uphill serve [EXPERIMENT_DIR] [--port 8080] [--host 127.0.0.1]`: the local web page on which
// lab technicians enter measurements (src/server/). Prints the address, serves until SIGINT or
// SIGTERM. Every acknowledged change is already on disk (journal + files), so stopping the
// server in any way, even `kill -9`, loses nothing that the page showed as saved. The page
// decodes video frames and calibrates (OpenCV): it runs in uphill-vision (vision_program.hpp).
#include <memory>

#include "commands.hpp"
#include "vision_program.hpp"
#if UPHILL_VISION_PROGRAM
#include <pthread.h>
#include <signal.h>

#include <iostream>
#include <thread>

#include "server/http_server.hpp"
#endif

namespace uphill::cli {
namespace {

struct ServeFlags {
  std::string directory = ".";
  std::string host = "127.0.0.1";
  int port = 8080;
};

void Serve(const ServeFlags& flags) {
#if !UPHILL_VISION_PROGRAM
  (void)flags;
  RunInVisionProgram();
#else
  ServerOptions options;
  options.directory = flags.directory;
  options.host = flags.host;
  options.port = flags.port;
  // Block SIGINT/SIGTERM in every thread (the server's threads inherit the mask) and wait for them
  // in one thread: stopping the server from a signal handler would not be async-signal-safe.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A browser that closes a connection mid-answer must not kill the server.
  signal(SIGPIPE, SIG_IGN);

  Server server(options);
  const int port = server.Bind();
  const std::string shown_host = flags.host.find(':') != std::string::npos ? "[" + flags.host + "]" : flags.host;
  std::cout << "uphill serve: http://" << shown_host << ":" << port << "/  (experiment "
            << flags.directory << "; " << server.store().recovery_note() << ")\n"
            << "Press Ctrl+C to stop; every saved row is already on disk." << std::endl;
  std::thread waiter([&] {
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    server.Stop();
  });
  server.Run();
  // Run returned: by a signal (the waiter is done) or by a failure (wake the waiter).
  pthread_kill(waiter.native_handle(), SIGTERM);
  waiter.join();
#endif
}

}  // namespace

void AddServeCommand(CLI::App& app) {
  auto flags = std::make_shared<ServeFlags>();
  CLI::App* serve = app.add_subcommand(
      "serve", "A local web page to enter measurements with live checks (every change saved at once)");
  serve->add_option("EXPERIMENT_DIR", flags->directory,
                    "The experiment folder (created by the page if it does not exist)");
  serve->add_option("--port", flags->port, "TCP port; 0 picks a free one")->check(CLI::Range(0, 65535));
  serve->add_option("--host", flags->host,
                    "Address to listen on (default 127.0.0.1: this computer only; the page has no login)");
  serve->callback([flags] { Serve(*flags); });
}

}  // namespace uphill::cli
