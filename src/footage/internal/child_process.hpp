// Child processes of the footage generator (povray, ffmpeg), started without a shell
// (posix_spawnp: arguments are passed as they are, no quoting), with their output going to a log
// file. Private to the footage layer.
#pragma once

#include <cstddef>
#include <string>
#include <sys/types.h>
#include <vector>

namespace uphill::internal {

struct ChildStatus {
  bool started = false;     // false: the program could not be started (not installed?)
  int exit_code = -1;       // when it exited normally
  int signal = 0;           // when a signal ended it
  double cpu_seconds = 0;   // user + system time of the child
  bool ok() const { return started && signal == 0 && exit_code == 0; }
};

// Runs argv (argv[0] looked up in PATH) in the folder `cwd` ("" : ours), stdout and stderr
// appended to `log_path`, and waits for it.
ChildStatus RunChild(const std::vector<std::string>& argv, const std::string& cwd, const std::string& log_path);

// A child that reads its standard input from us (ffmpeg reading raw frames). Writing never
// raises SIGPIPE: the input is a socket written with MSG_NOSIGNAL, so a child that died shows as
// a failed Write, and Finish() says why.
class ChildInput {
 public:
  ChildInput(const std::vector<std::string>& argv, const std::string& log_path);
  ~ChildInput();  // kills and reaps the child if Finish() was not called
  ChildInput(const ChildInput&) = delete;
  ChildInput& operator=(const ChildInput&) = delete;

  bool started() const { return pid_ > 0; }
  // False when the child no longer reads (it exited, or never started).
  bool Write(const void* data, std::size_t size);
  // Closes the child's input and waits for it.
  ChildStatus Finish();

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
};

// The last `lines` lines of a text file ("" if it cannot be read), for error messages.
std::string TailOfFile(const std::string& path, int lines = 6);

}  // namespace uphill::internal
