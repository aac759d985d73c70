// ContainedDirectory: a folder that a program reads and writes only beneath, whatever is put
// inside it. The folder's own path is resolved once, when it is opened (links in the path the
// user gave are the user's choice); below it every path is walked one component at a time with
// O_NOFOLLOW from the open folder's descriptor, so a symbolic link at any level, to a file or to
// a folder, is refused instead of followed, and ".." or an absolute path never get out. Used by
// `uphill serve`, whose experiment folder may be shared with other people and programs.
//
// Relative paths are '/'-separated components; "", ".", ".." and a leading '/' are refused
// (InputError naming the path). What is found in the way (a link, a device, a folder where a
// file is expected) and failed system calls are EnvironmentError naming the path.
//
// What it does not defend against: another local user who can write into the folder and swaps
// a component for a link between two of its system calls (a race on a folder they share). Each
// single read, write or rename is contained; a sequence of them is not a transaction.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace uphill {

class ContainedDirectory {
 public:
  enum class Kind { kAbsent, kFile, kDirectory, kLink, kOther };

  // Resolves `path` (realpath) and opens it. Throws EnvironmentError when it does not exist, is
  // not a folder, or cannot be opened.
  static ContainedDirectory Open(const std::string& path);

  ContainedDirectory(ContainedDirectory&& other) noexcept;
  ContainedDirectory& operator=(ContainedDirectory&& other) noexcept;
  ContainedDirectory(const ContainedDirectory&) = delete;
  ContainedDirectory& operator=(const ContainedDirectory&) = delete;
  ~ContainedDirectory();

  // The resolved absolute path (for messages and for libraries that take paths).
  const std::string& path() const { return path_; }
  int fd() const { return fd_; }

  // What the last component of `relative` is, not following a link there. The components before
  // it must be real folders (a link among them: EnvironmentError).
  Kind KindOf(const std::string& relative) const;

  // The content of the regular file `relative`, or nullopt when it does not exist. A link or
  // anything but a regular file there, or a file over `max_bytes`: EnvironmentError.
  std::optional<std::string> ReadFile(const std::string& relative, std::size_t max_bytes) const;

  // Replaces the regular file `relative` atomically (io/atomic_file.hpp), or creates it.
  void WriteFileAtomically(const std::string& relative, std::string_view content) const;

  // The subfolder `relative`, created (mode 0755, each missing level) when `create`. A link or a
  // file in the way: EnvironmentError.
  ContainedDirectory Subdirectory(const std::string& relative, bool create) const;

  // A new empty private subfolder named `prefix` + random suffix (mode 0700), for staging files.
  ContainedDirectory MakeStagingDirectory(const std::string& prefix) const;

  // Opens `relative` for appending (created with mode 0644 when absent), never through a link.
  // Returns the descriptor (the caller closes it).
  int OpenForAppend(const std::string& relative) const;

  // The names of the regular files directly in this folder, sorted.
  std::vector<std::string> RegularFiles() const;

  // Moves the regular file `name` of this folder to `to`/`target` (never over anything but a
  // regular file), and fsyncs `to`.
  void MoveFile(const std::string& name, const ContainedDirectory& to, const std::string& target) const;

  // Removes this folder's regular files and then the (now empty) folder `relative` below the
  // parent it was made in. Best effort: used to clean up a staging folder.
  static void RemoveStaging(const ContainedDirectory& parent, ContainedDirectory staging);

  // Renames `from` to `to` inside this folder (both single components); fails if `to` exists.
  void RenameNoReplace(const std::string& from, const std::string& to) const;

  // fsync of the folder itself (a new name in it survives a crash).
  void Sync() const;

 private:
  ContainedDirectory(std::string path, int fd) : path_(std::move(path)), fd_(fd) {}
  // Opens the folder holding the last component of `relative` (the descriptor of this folder
  // itself when `relative` has one component; then *owned is false). Returns the last component.
  std::string OpenParent(const std::string& relative, int* parent_fd, bool* owned, bool create) const;

  std::string path_;
  int fd_ = -1;
};

// The components of `relative`; throws InputError(relative, rule) for an empty, ".", ".." or
// absolute path.
std::vector<std::string> SplitContainedPath(const std::string& relative);

}  // namespace uphill
