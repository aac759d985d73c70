#include "io/contained_directory.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <utility>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "io/atomic_file.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

[[noreturn]] void Fail(const std::string& path, const std::string& what, int error) {
  throw EnvironmentError(path + ": " + what + ": " + std::strerror(error));
}

std::string Join(const std::string& a, const std::string& b) { return (std::filesystem::path(a) / b).string(); }

ContainedDirectory::Kind KindAt(int directory_fd, const std::string& name) {
  struct stat st {};
  if (::fstatat(directory_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
    if (errno == ENOENT) return ContainedDirectory::Kind::kAbsent;
    return ContainedDirectory::Kind::kOther;
  }
  if (S_ISREG(st.st_mode)) return ContainedDirectory::Kind::kFile;
  if (S_ISDIR(st.st_mode)) return ContainedDirectory::Kind::kDirectory;
  if (S_ISLNK(st.st_mode)) return ContainedDirectory::Kind::kLink;
  return ContainedDirectory::Kind::kOther;
}

std::string Describe(ContainedDirectory::Kind kind) {
  switch (kind) {
    case ContainedDirectory::Kind::kAbsent: return "absent";
    case ContainedDirectory::Kind::kFile: return "a file";
    case ContainedDirectory::Kind::kDirectory: return "a folder";
    case ContainedDirectory::Kind::kLink: return "a symbolic link";
    case ContainedDirectory::Kind::kOther: return "not a regular file or folder";
  }
  return "";
}

// Opens the subfolder `name` of `directory_fd`, never through a link; creates it when asked.
int OpenSubfolder(int directory_fd, const std::string& shown, const std::string& name, bool create) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::openat(directory_fd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0) return fd;
    const int saved = errno;
    const ContainedDirectory::Kind kind = KindAt(directory_fd, name);
    if (kind == ContainedDirectory::Kind::kAbsent && create && attempt == 0) {
      if (::mkdirat(directory_fd, name.c_str(), 0755) != 0 && errno != EEXIST) Fail(shown, "cannot create the folder", errno);
      continue;
    }
    if (kind == ContainedDirectory::Kind::kAbsent) throw EnvironmentError(shown + ": does not exist");
    if (kind != ContainedDirectory::Kind::kDirectory)
      throw EnvironmentError(shown + ": is " + Describe(kind) +
                             ", not a folder: refused (nothing is read or written outside the folder)");
    Fail(shown, "cannot open the folder", saved);
  }
  throw EnvironmentError(shown + ": cannot be created");
}

}  // namespace

std::vector<std::string> SplitContainedPath(const std::string& relative) {
  if (relative.empty()) throw InputError("path", "is empty");
  if (relative.front() == '/') throw InputError(relative, "must be a path inside the folder, not an absolute path");
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t slash = relative.find('/', start);
    const std::string part = relative.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (part.empty() || part == "." || part == "..")
      throw InputError(relative, "must be a plain path inside the folder (no empty, '.' or '..' parts)");
    if (part.find('\0') != std::string::npos) throw InputError(relative, "must not contain a NUL character");
    parts.push_back(part);
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return parts;
}

ContainedDirectory ContainedDirectory::Open(const std::string& path) {
  char resolved[PATH_MAX];
  if (::realpath(path.c_str(), resolved) == nullptr) {
    if (errno == ENOENT) throw EnvironmentError(path + ": does not exist");
    if (errno == ENOTDIR) throw EnvironmentError(path + ": a part of the path is not a folder");
    Fail(path, "cannot be resolved", errno);
  }
  const int fd = ::open(resolved, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOTDIR) throw EnvironmentError(path + ": is a file, not a folder");
    Fail(path, "cannot open the folder", errno);
  }
  return ContainedDirectory(resolved, fd);
}

ContainedDirectory::ContainedDirectory(ContainedDirectory&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

ContainedDirectory& ContainedDirectory::operator=(ContainedDirectory&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

ContainedDirectory::~ContainedDirectory() {
  if (fd_ >= 0) ::close(fd_);
}

std::string ContainedDirectory::OpenParent(const std::string& relative, int* parent_fd, bool* owned,
                                           bool create) const {
  const std::vector<std::string> parts = SplitContainedPath(relative);
  int fd = fd_;
  bool fd_owned = false;
  std::string shown = path_;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    shown = Join(shown, parts[i]);
    int next = -1;
    try {
      next = OpenSubfolder(fd, shown, parts[i], create);
    } catch (...) {
      if (fd_owned) ::close(fd);
      throw;
    }
    if (fd_owned) ::close(fd);
    fd = next;
    fd_owned = true;
  }
  *parent_fd = fd;
  *owned = fd_owned;
  return parts.back();
}

ContainedDirectory::Kind ContainedDirectory::KindOf(const std::string& relative) const {
  const std::vector<std::string> parts = SplitContainedPath(relative);
  int fd = fd_;
  std::string shown = path_;
  Kind kind = Kind::kAbsent;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    kind = KindAt(fd, parts[i]);
    if (i + 1 == parts.size() || kind == Kind::kAbsent) break;
    shown = Join(shown, parts[i]);
    int next = -1;
    try {
      next = OpenSubfolder(fd, shown, parts[i], false);
    } catch (...) {
      if (fd != fd_) ::close(fd);
      throw;
    }
    if (fd != fd_) ::close(fd);
    fd = next;
  }
  if (fd != fd_) ::close(fd);
  return kind;
}

std::optional<std::string> ContainedDirectory::ReadFile(const std::string& relative, std::size_t max_bytes) const {
  int parent = -1;
  bool owned = false;
  const std::string shown = Join(path_, relative);
  if (KindOf(relative) == Kind::kAbsent) return std::nullopt;
  const std::string name = OpenParent(relative, &parent, &owned, false);
  const int fd = ::openat(parent, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  const int saved = errno;
  const Kind kind = fd < 0 ? KindAt(parent, name) : Kind::kFile;
  if (owned) ::close(parent);
  if (fd < 0) {
    if (kind == Kind::kAbsent) return std::nullopt;
    if (kind != Kind::kFile)
      throw EnvironmentError(shown + ": is " + Describe(kind) + ", not a regular file: refused (nothing is read outside the folder)");
    Fail(shown, "cannot be opened", saved);
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw EnvironmentError(shown + ": is not a regular file: refused");
  }
  if (static_cast<std::size_t>(st.st_size) > max_bytes) {
    ::close(fd);
    throw EnvironmentError(shown + ": is larger than " + std::to_string(max_bytes) + " bytes");
  }
  std::string content;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      Fail(shown, "cannot be read", e);
    }
    if (n == 0) break;
    content.append(buffer, static_cast<std::size_t>(n));
    if (content.size() > max_bytes) {
      ::close(fd);
      throw EnvironmentError(shown + ": is larger than " + std::to_string(max_bytes) + " bytes");
    }
  }
  ::close(fd);
  return content;
}

void ContainedDirectory::WriteFileAtomically(const std::string& relative, std::string_view content) const {
  int parent = -1;
  bool owned = false;
  const std::string name = OpenParent(relative, &parent, &owned, false);
  const std::string parent_path = std::filesystem::path(Join(path_, relative)).parent_path().string();
  try {
    WriteFileAtomicallyAt(parent, parent_path, name, content);
  } catch (...) {
    if (owned) ::close(parent);
    throw;
  }
  if (owned) ::close(parent);
}

ContainedDirectory ContainedDirectory::Subdirectory(const std::string& relative, bool create) const {
  int parent = -1;
  bool owned = false;
  const std::string name = OpenParent(relative, &parent, &owned, create);
  const std::string shown = Join(path_, relative);
  int fd = -1;
  try {
    fd = OpenSubfolder(parent, shown, name, create);
  } catch (...) {
    if (owned) ::close(parent);
    throw;
  }
  if (owned) ::close(parent);
  return ContainedDirectory(shown, fd);
}

ContainedDirectory ContainedDirectory::MakeStagingDirectory(const std::string& prefix) const {
  for (int attempt = 0; attempt < 100; ++attempt) {
    unsigned long long r = 0;
    if (::getrandom(&r, sizeof r, 0) != static_cast<ssize_t>(sizeof r)) r = static_cast<unsigned long long>(::getpid()) * 7919u + attempt;
    char suffix[24];
    std::snprintf(suffix, sizeof suffix, "%016llx", r);
    const std::string name = prefix + suffix;
    if (::mkdirat(fd_, name.c_str(), 0700) == 0) {
      const int fd = ::openat(fd_, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
      if (fd < 0) Fail(Join(path_, name), "cannot open the new folder", errno);
      return ContainedDirectory(Join(path_, name), fd);
    }
    if (errno != EEXIST) Fail(Join(path_, name), "cannot create a staging folder", errno);
  }
  throw EnvironmentError(path_ + ": cannot create a staging folder");
}

int ContainedDirectory::OpenForAppend(const std::string& relative) const {
  int parent = -1;
  bool owned = false;
  const std::string name = OpenParent(relative, &parent, &owned, false);
  const std::string shown = Join(path_, relative);
  const int fd = ::openat(parent, name.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  const int saved = errno;
  const Kind kind = fd < 0 ? KindAt(parent, name) : Kind::kFile;
  if (owned) ::close(parent);
  if (fd < 0) {
    if (kind != Kind::kFile && kind != Kind::kAbsent)
      throw EnvironmentError(shown + ": is " + Describe(kind) + ", not a regular file: refused");
    Fail(shown, "cannot be opened for writing", saved);
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw EnvironmentError(shown + ": is not a regular file: refused");
  }
  ::fcntl(fd, F_SETFL, O_WRONLY | O_APPEND);  // blocking writes from here on
  return fd;
}

std::vector<std::string> ContainedDirectory::RegularFiles() const {
  std::vector<std::string> names;
  const int fd = ::openat(fd_, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) Fail(path_, "cannot be listed", errno);
  DIR* dir = ::fdopendir(fd);
  if (dir == nullptr) {
    const int e = errno;
    ::close(fd);
    Fail(path_, "cannot be listed", e);
  }
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    if (name == "." || name == "..") continue;
    if (KindAt(fd_, name) == Kind::kFile) names.push_back(name);
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

void ContainedDirectory::MoveFile(const std::string& name, const ContainedDirectory& to, const std::string& target) const {
  if (KindAt(fd_, name) != Kind::kFile) throw EnvironmentError(Join(path_, name) + ": is not a regular file: not moved");
  RenameIntoPlaceAt(fd_, name, to.fd_, to.path_, target);
}

void ContainedDirectory::RemoveStaging(const ContainedDirectory& parent, ContainedDirectory staging) {
  try {
    for (const std::string& name : staging.RegularFiles()) ::unlinkat(staging.fd_, name.c_str(), 0);
  } catch (const EnvironmentError&) {
  }
  const std::string name = std::filesystem::path(staging.path_).filename().string();
  ::unlinkat(parent.fd_, name.c_str(), AT_REMOVEDIR);
}

void ContainedDirectory::RenameNoReplace(const std::string& from, const std::string& to) const {
  SplitContainedPath(from);
  SplitContainedPath(to);
  if (::renameat2(fd_, from.c_str(), fd_, to.c_str(), RENAME_NOREPLACE) != 0)
    Fail(Join(path_, to), "cannot rename " + from + " to it", errno);
  Sync();
}

void ContainedDirectory::Sync() const { ::fsync(fd_); }

}  // namespace uphill
