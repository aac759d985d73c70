// WriteFileAtomically: replace a file so that a reader, or a crash, sees either the old content
// or the new one, never a half-written file (write to a temporary in the same directory, fsync,
// rename over the target, fsync the directory). A failure at any step removes the temporary: the
// target is then exactly as before, or absent if it was absent.
//
// Only a regular file is ever replaced: a directory, a device node, a pipe, a socket or a
// symbolic link at the target's name is refused (EnvironmentError) and left alone, so a
// mistyped output can never turn /dev/full into a file or write through a link.
#pragma once

#include <string>
#include <string_view>

namespace uphill {

// Throws EnvironmentError naming the path and the failing step (or the kind of thing in the way).
void WriteFileAtomically(const std::string& path, std::string_view content);

// The same, relative to an open directory `directory_fd` (shown as `directory_name` in
// messages); `name` is one path component (no '/'). The building block of ContainedDirectory.
void WriteFileAtomicallyAt(int directory_fd, const std::string& directory_name, const std::string& name,
                           std::string_view content);

// Moves an already written, fsynced file into place under the same rules (never over something
// that is not a regular file), then fsyncs the target directory. `from` and `to` are single
// components relative to their directory descriptors. Throws EnvironmentError.
void RenameIntoPlaceAt(int from_fd, const std::string& from, int to_fd, const std::string& to_directory_name,
                       const std::string& to);

}  // namespace uphill
