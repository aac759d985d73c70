// EnvironmentError: the computer, not the input's content, refused: a file or folder that cannot
// be written or read (permissions, a full disk, a read-only folder), a helper program that is
// missing (gnuplot, povray, ffmpeg), a port in use. Like InputError (model/input_error.hpp) it is
// the user's to fix, never a bug: the program reports it in one line naming the path, program or
// port and the system's reason, and exits with status 2 (docs/exit-codes.md).
#pragma once

#include <stdexcept>
#include <string>

namespace uphill {

class EnvironmentError : public std::runtime_error {
 public:
  explicit EnvironmentError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace uphill
