#include "video_upload.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <regex>

#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill::internal {

std::string ReceiveUpload(const ContainedDirectory& folder, const std::string& directory, const std::string& name,
                          std::size_t declared_bytes, std::size_t max_bytes, const BodyReader& read,
                          const std::function<void(const std::string& staged_path)>& check) {
  static const std::regex ok("[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}");
  static const std::regex video(".*\\.(mp4|avi|mkv|mov|m4v|webm|MP4|AVI|MKV|MOV|M4V|WEBM)");
  if (!std::regex_match(name, ok) || name.find("..") != std::string::npos)
    throw InputError("name", "a file name of 1 to 100 letters, digits, '.', '-' or '_' (rename the file)");
  if (!std::regex_match(name, video)) throw InputError("name", name + ": not a video file name (.mp4, .avi, .mkv, .mov, .m4v, .webm)");
  if (declared_bytes > max_bytes)
    throw InputError("upload", name + " is " + std::to_string(declared_bytes >> 20) + " MiB: larger than the limit of " +
                                   std::to_string(max_bytes >> 20) + " MiB (uphill serve --max-upload)");
  const std::string target = directory + "/" + name;
  if (folder.KindOf(target) != ContainedDirectory::Kind::kAbsent)
    throw InputError("name", target + " exists already in the experiment folder: pick it from the list, or rename the file");
  const ContainedDirectory into = folder.Subdirectory(directory, true);
  ContainedDirectory staging = into.MakeStagingDirectory(".upload-");
  try {
    const int fd = staging.OpenForAppend("upload");
    std::size_t received = 0;
    std::string failure;
    const bool whole = read([&](const char* data, std::size_t n) {
      received += n;
      if (received > max_bytes) {
        failure = "more than the limit of " + std::to_string(max_bytes >> 20) + " MiB";
        return false;
      }
      for (std::size_t done = 0; done < n;) {
        const ssize_t w = ::write(fd, data + done, n - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
          failure = std::string("cannot be written: ") + std::strerror(errno);
          return false;
        }
        done += static_cast<std::size_t>(w);
      }
      return true;
    });
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!failure.empty()) throw InputError("upload", name + ": " + failure + "; nothing was kept");
    if (!whole || received != declared_bytes)
      throw InputError("upload", name + ": the upload was cut off (" + std::to_string(received) + " of " +
                                     std::to_string(declared_bytes) + " bytes); nothing was kept");
    if (!synced) throw EnvironmentError(staging.path() + "/upload: fsync failed: nothing was kept");
    check(staging.path() + "/upload");
    if (folder.KindOf(target) != ContainedDirectory::Kind::kAbsent)
      throw InputError("name", target + " appeared meanwhile: nothing was replaced");
    staging.MoveFile("upload", into, name);
  } catch (...) {
    ContainedDirectory::RemoveStaging(into, std::move(staging));
    throw;
  }
  ContainedDirectory::RemoveStaging(into, std::move(staging));
  return target;
}

}  // namespace uphill::internal
