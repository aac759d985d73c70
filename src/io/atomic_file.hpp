// WriteFileAtomically: replace a file so that a reader, or a crash, sees either the old content
// or the new one, never a half-written file (write to a temporary in the same directory, fsync,
// rename over the target, fsync the directory).
#pragma once

#include <string>
#include <string_view>

namespace uphill {

// Throws std::runtime_error naming the path and the failing system call.
void WriteFileAtomically(const std::string& path, std::string_view content);

}  // namespace uphill
