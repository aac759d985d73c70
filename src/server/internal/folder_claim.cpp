#include "folder_claim.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>

#include "model/environment_error.hpp"

namespace uphill::internal {
namespace {

// The names in the open folder `fd` (not "." or ".."), or nullopt when it cannot be listed.
std::optional<std::vector<std::string>> Names(int fd) {
  const int listing = ::openat(fd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (listing < 0) return std::nullopt;
  DIR* dir = ::fdopendir(listing);
  if (dir == nullptr) {
    ::close(listing);
    return std::nullopt;
  }
  std::vector<std::string> names;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  ::closedir(dir);
  return names;
}

bool IsRegularFileAt(int fd, const std::string& name) {
  struct stat st {};
  return ::fstatat(fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode);
}

// Removes the staging folder `name` of `parent` if it is a real folder holding only regular
// files (what the server puts there); true when it is gone.
bool RemoveStagingFolder(int parent, const std::string& name) {
  const int fd = ::openat(parent, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;  // a link, a file, or unreadable: not ours to remove
  const std::optional<std::vector<std::string>> names = Names(fd);
  bool ours = names.has_value();
  if (ours)
    for (const std::string& n : *names) ours = ours && IsRegularFileAt(fd, n);
  if (ours)
    for (const std::string& n : *names) ::unlinkat(fd, n.c_str(), 0);
  ::close(fd);
  return ours && ::unlinkat(parent, name.c_str(), AT_REMOVEDIR) == 0;
}

void RemoveIn(const ContainedDirectory& folder, const std::string& relative, const std::string& prefix,
              std::vector<std::string>& removed) {
  try {
    std::optional<ContainedDirectory> sub;
    if (!relative.empty()) {
      if (folder.KindOf(relative) != ContainedDirectory::Kind::kDirectory) return;
      sub.emplace(folder.Subdirectory(relative, false));
    }
    const ContainedDirectory& where = sub ? *sub : folder;
    const std::optional<std::vector<std::string>> names = Names(where.fd());
    if (!names) return;
    for (const std::string& name : *names)
      if (IsStagingName(name, prefix) && RemoveStagingFolder(where.fd(), name))
        removed.push_back(relative.empty() ? name : relative + "/" + name);
  } catch (const EnvironmentError&) {
    // A link or a non-folder where the upload folder would be: nothing of ours can be there.
  }
}

}  // namespace

bool IsStagingName(const std::string& name, const std::string& prefix) {
  if (name.size() != prefix.size() + 16 || name.compare(0, prefix.size(), prefix) != 0) return false;
  for (std::size_t i = prefix.size(); i < name.size(); ++i)
    if (!((name[i] >= '0' && name[i] <= '9') || (name[i] >= 'a' && name[i] <= 'f'))) return false;
  return true;
}

std::vector<std::string> RemoveStaleStaging(const ContainedDirectory& folder) {
  std::vector<std::string> removed;
  RemoveIn(folder, "", kReportStagingPrefix, removed);
  RemoveIn(folder, kVideoUploadFolder, kUploadStagingPrefix, removed);
  RemoveIn(folder, kViewUploadFolder, kUploadStagingPrefix, removed);
  return removed;
}

FolderClaim::FolderClaim(const ContainedDirectory& folder) {
  fd_ = ::openat(folder.fd(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) return;
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) {
    RemoveStaleStaging(folder);
    ::flock(fd_, LOCK_SH);  // a conversion: never waits
    return;
  }
  // Another server holds it (or is removing its stale staging folders: a moment).
  int rc;
  while ((rc = ::flock(fd_, LOCK_SH)) != 0 && errno == EINTR) {
  }
  if (rc != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

FolderClaim::~FolderClaim() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace uphill::internal
