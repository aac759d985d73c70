#include "video_upload.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <regex>

#include "folder_claim.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill::internal {

const UploadKind& VideoUpload() {
  static const UploadKind kind{"video", {".mp4", ".avi", ".mkv", ".mov", ".m4v", ".webm"}};
  return kind;
}

const UploadKind& ImageUpload() {
  static const UploadKind kind{"image", {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"}};
  return kind;
}

namespace {

bool HasExtension(const std::string& name, const UploadKind& kind) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const std::string& ext : kind.extensions)
    if (lower.size() > ext.size() && lower.compare(lower.size() - ext.size(), ext.size(), ext) == 0) return true;
  return false;
}

std::string Listed(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// The name with the bytes a path cannot hold in a name, and other control bytes, as %XX.
std::string Shown(const std::string& name) {
  static const char* kHex = "0123456789ABCDEF";
  std::string out;
  for (const char c : name.substr(0, 140)) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7F || c == '/' || c == '%') out.append({'%', kHex[b >> 4], kHex[b & 15]});
    else out += c;
  }
  return name.size() > 140 ? out + "…" : out;
}

}  // namespace

void CheckUploadName(const std::string& name, const UploadKind& kind) {
  static const std::regex ok("[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}");
  if (!std::regex_match(name, ok) || name.find("..") != std::string::npos)
    throw InputError("name", "a file name of 1 to 100 letters, digits, '.', '-' or '_', not starting with '.' (got \"" +
                                 Shown(name) + "\", " + std::to_string(name.size()) + " characters: rename the file)");
  if (!HasExtension(name, kind))
    throw InputError("name", name + ": not " + (kind.what == "image" ? "an " : "a ") + kind.what + " file name (" +
                                 Listed(kind.extensions) + ")");
}

ContainedDirectory::Kind KindInFolder(const ContainedDirectory& folder, const std::string& relative,
                                      const std::string& field) {
  try {
    return folder.KindOf(relative);
  } catch (const EnvironmentError& e) {
    std::string message = e.what();
    const std::string root = folder.path() + "/";
    if (message.rfind(root, 0) == 0) message.erase(0, root.size());
    throw InputError(field, relative + ": refused: " + message);
  }
}

std::string ReceiveUpload(const ContainedDirectory& folder, const std::string& directory, const std::string& name,
                          const UploadKind& kind, std::size_t declared_bytes, std::size_t max_bytes,
                          const BodyReader& read, const std::function<void(const std::string& staged_path)>& check) {
  CheckUploadName(name, kind);
  if (declared_bytes > max_bytes)
    throw InputError("upload", name + " is " + std::to_string(declared_bytes >> 20) + " MiB: larger than the limit of " +
                                   std::to_string(max_bytes >> 20) + " MiB");
  const std::string target = directory + "/" + name;
  if (KindInFolder(folder, target, "name") != ContainedDirectory::Kind::kAbsent)
    throw InputError("name", target + " exists already in the experiment folder: pick it from the list, or rename the file");
  const ContainedDirectory into = folder.Subdirectory(directory, true);
  ContainedDirectory staging = into.MakeStagingDirectory(kUploadStagingPrefix);
  try {
    const int fd = staging.OpenForAppend("upload");
    std::size_t received = 0;
    std::string failure, disk_failure;
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
          disk_failure = w < 0 ? std::strerror(errno) : "nothing written";
          return false;
        }
        done += static_cast<std::size_t>(w);
      }
      return true;
    });
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!disk_failure.empty())
      throw EnvironmentError(target + ": cannot be written to the experiment folder's disk (" + disk_failure +
                             "): nothing was kept");
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
