#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace uphill {
namespace {

[[noreturn]] void Fail(const std::string& what, const std::string& path) {
  throw std::runtime_error(path + ": " + what + " failed: " + std::strerror(errno));
}

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view content) {
  const std::filesystem::path target(path);
  const std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : ".";
  // Built by append: GCC 12 warns falsely (-Wrestrict) on "." + std::string + "…".
  std::string stem = ".";
  stem.append(target.filename().string()).append(".tmp-XXXXXX");
  const std::string pattern = (dir / stem).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0) Fail("creating a temporary file", path);
  const std::string tmp(name.data());
  auto cleanup = [&](const std::string& what) {
    const int saved = errno;
    close(fd);
    unlink(tmp.c_str());
    errno = saved;
    Fail(what, path);
  };
  size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      cleanup("write");
    }
    written += static_cast<size_t>(n);
  }
  if (fchmod(fd, 0644) != 0) cleanup("fchmod");
  if (fsync(fd) != 0) cleanup("fsync");
  if (close(fd) != 0) {
    unlink(tmp.c_str());
    Fail("close", path);
  }
  if (rename(tmp.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    unlink(tmp.c_str());
    errno = saved;
    Fail("rename", path);
  }
  const int dfd = open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    fsync(dfd);  // best effort: the rename is durable once the directory is synced
    close(dfd);
  }
}

}  // namespace uphill
