// Which servers hold an experiment folder, and the staging folders a killed server leaves behind.
// Private to src/server/.
//
// The server stages what it writes in bulk in private hidden folders beside the target (an
// upload: `.upload-` + 16 hex digits in the folder it goes to; the report: `.report-staging-` +
// 16 hex digits in the experiment folder) and removes them when done. A server killed meanwhile
// leaves one behind. Such a folder is never read; at start the server removes those of its own
// making, but only when no other server is using the folder: another server's staging folder is
// live.
//
// How servers know of each other: each running server holds a shared flock(2) on the experiment
// folder (on a descriptor of its own, released by the kernel when the process dies, even by
// SIGKILL). A server that gets the lock exclusively at start is alone: it removes the stale
// staging folders and then shares the lock.
#pragma once

#include <string>
#include <vector>

#include "io/contained_directory.hpp"

namespace uphill::internal {

inline constexpr const char* kUploadStagingPrefix = ".upload-";
inline constexpr const char* kReportStagingPrefix = ".report-staging-";
// The folders (relative to the experiment folder) that uploads are staged in.
inline constexpr const char* kVideoUploadFolder = "videos";
inline constexpr const char* kViewUploadFolder = "calibration/views";

// Whether `name` is one of the server's staging folders' names for `prefix`: the prefix and
// exactly 16 lowercase hex digits (ContainedDirectory::MakeStagingDirectory's suffix).
bool IsStagingName(const std::string& name, const std::string& prefix);

class FolderClaim {
 public:
  // Claims `folder` for this server for the claim's lifetime (shared with other servers). When no
  // other server holds it, first removes the stale staging folders (RemoveStaleStaging). A lock
  // the file system refuses (e.g. some network file systems) claims nothing and removes nothing.
  explicit FolderClaim(const ContainedDirectory& folder);
  ~FolderClaim();
  FolderClaim(const FolderClaim&) = delete;
  FolderClaim& operator=(const FolderClaim&) = delete;

 private:
  int fd_ = -1;
};

// Removes, in the experiment folder and in its upload folders, each real folder (not a link) whose
// name IsStagingName for the staging prefix used there and that holds only regular files; returns
// their paths relative to `folder`. Anything else, of any name, is left alone. Call only when no
// other server uses the folder.
std::vector<std::string> RemoveStaleStaging(const ContainedDirectory& folder);

}  // namespace uphill::internal
