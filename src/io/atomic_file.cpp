#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "internal/file_kind.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

std::string Shown(const std::string& directory_name, const std::string& name) {
  if (directory_name.empty() || directory_name == ".") return name;
  return (std::filesystem::path(directory_name) / name).string();
}

[[noreturn]] void Fail(const std::string& what, const std::string& path, int error) {
  throw EnvironmentError(path + ": " + what + " failed: " + std::strerror(error));
}

// What is in the way at `name`, in words, or "" for nothing or a regular file.
std::string ObstacleAt(int directory_fd, const std::string& name) {
  struct stat st {};
  if (::fstatat(directory_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return "";
  return internal::FileKindName(st.st_mode);
}

void RefuseObstacle(int directory_fd, const std::string& shown, const std::string& name) {
  const std::string obstacle = ObstacleAt(directory_fd, name);
  if (!obstacle.empty())
    throw EnvironmentError(shown + ": is " + obstacle + ", not a regular file: not replaced");
}

void SyncDirectory(int directory_fd) {
  ::fsync(directory_fd);  // best effort: the rename is durable once the directory is synced
}

// ".NAME.tmp-<16 hex>", created exclusively (never follows or reuses anything).
int CreateTemporary(int directory_fd, const std::string& name, std::string* temporary) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    unsigned long long r = 0;
    if (::getrandom(&r, sizeof r, 0) != static_cast<ssize_t>(sizeof r)) r ^= static_cast<unsigned long long>(::getpid()) * 2654435761u + attempt;
    char suffix[24];
    std::snprintf(suffix, sizeof suffix, ".tmp-%016llx", r);
    // Built by append: GCC 12 warns falsely (-Wrestrict) on "." + std::string + "…".
    std::string candidate = ".";
    candidate.append(name.substr(0, 200)).append(suffix);
    const int fd = ::openat(directory_fd, candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) {
      *temporary = candidate;
      return fd;
    }
    if (errno != EEXIST) return -1;
  }
  errno = EEXIST;
  return -1;
}

}  // namespace

void WriteFileAtomicallyAt(int directory_fd, const std::string& directory_name, const std::string& name,
                           std::string_view content) {
  const std::string shown = Shown(directory_name, name);
  RefuseObstacle(directory_fd, shown, name);
  std::string tmp;
  const int fd = CreateTemporary(directory_fd, name, &tmp);
  if (fd < 0) Fail("creating a temporary file", shown, errno);
  const auto cleanup = [&](const std::string& what) {
    const int saved = errno;
    ::close(fd);
    ::unlinkat(directory_fd, tmp.c_str(), 0);
    Fail(what, shown, saved);
  };
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      cleanup("write");
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fchmod(fd, 0644) != 0) cleanup("fchmod");
  if (::fsync(fd) != 0) cleanup("fsync");
  if (::close(fd) != 0) {
    const int saved = errno;
    ::unlinkat(directory_fd, tmp.c_str(), 0);
    Fail("close", shown, saved);
  }
  try {
    RenameIntoPlaceAt(directory_fd, tmp, directory_fd, directory_name, name);
  } catch (...) {
    ::unlinkat(directory_fd, tmp.c_str(), 0);
    throw;
  }
}

void RenameIntoPlaceAt(int from_fd, const std::string& from, int to_fd, const std::string& to_directory_name,
                       const std::string& to) {
  const std::string shown = Shown(to_directory_name, to);
  // Checked just before the rename: a folder in the way would make rename fail anyway, but a
  // device node or a link would be silently replaced.
  RefuseObstacle(to_fd, shown, to);
  if (::renameat(from_fd, from.c_str(), to_fd, to.c_str()) != 0) Fail("rename", shown, errno);
  SyncDirectory(to_fd);
}

void WriteFileAtomically(const std::string& path, std::string_view content) {
  const std::filesystem::path target(path);
  if (!target.has_filename()) throw EnvironmentError(path + ": names a folder, not a file");
  const std::string directory = target.has_parent_path() ? target.parent_path().string() : ".";
  const int directory_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (directory_fd < 0) {
    const int saved = errno;
    if (saved == ENOENT) throw EnvironmentError(path + ": the folder " + directory + " does not exist");
    if (saved == ENOTDIR) throw EnvironmentError(path + ": " + directory + " is not a folder");
    Fail("opening the folder " + directory, path, saved);
  }
  try {
    WriteFileAtomicallyAt(directory_fd, target.has_parent_path() ? directory : "", target.filename().string(),
                          content);
  } catch (...) {
    ::close(directory_fd);
    throw;
  }
  ::close(directory_fd);
}

}  // namespace uphill
