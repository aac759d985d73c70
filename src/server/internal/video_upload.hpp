// An upload of a file into the experiment folder (a trial's recording, a chessboard view):
// streamed to disk, never held in memory, size-limited, and atomic. Private to src/server/.
//
// The bytes go into a private staging folder inside the target folder (same file system), are
// fsynced, checked (e.g. that OpenCV reads them as a video), and only then renamed into place and
// the folder fsynced. A connection cut off mid-upload, a body larger than the limit or a failed
// check removes the staging folder: nothing is left behind, and no file of that name appears.
// (A server killed mid-upload leaves its staging folder, `.upload-*`, hidden and never read; the
// next server to start alone on the folder removes it: folder_claim.hpp.)
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "io/contained_directory.hpp"

namespace uphill::internal {

// Reads the body chunk by chunk, handing each to `sink` (false from the sink stops reading);
// returns false when the body could not be read whole.
using BodyReader = std::function<bool(const std::function<bool(const char*, std::size_t)>& sink)>;

// What may be uploaded: its kind for messages ("video") and the file name extensions accepted
// (lower case, with the dot; matched without regard to case).
struct UploadKind {
  std::string what;
  std::vector<std::string> extensions;
};
const UploadKind& VideoUpload();
const UploadKind& ImageUpload();  // .png .jpg .jpeg .bmp .tif .tiff: what OpenCV calibrates from

// Throws InputError("name") for a name that is not 1-100 letters, digits, '.', '-', '_' (not
// starting with '.') or has none of the kind's extensions, showing the name as sent (a '/' or a
// NUL it holds as %2F, %00).
void CheckUploadName(const std::string& name, const UploadKind& kind);

// folder.KindOf(relative), with a link or a file where a folder of the path should be refused
// as InputError(field) naming the path (relative to the folder) and the rule.
ContainedDirectory::Kind KindInFolder(const ContainedDirectory& folder, const std::string& relative,
                                      const std::string& field);

// Stores the body as `directory`/`name` (directory created) and returns that relative path.
// Throws InputError("name") for a name CheckUploadName refuses, InputError("upload") for a body
// beyond `max_bytes` or cut off, whatever `check` throws when it refuses the staged file,
// InputError("name") when the name is taken or a folder of its path is a link; EnvironmentError
// when the disk fails (full, or failing to write).
std::string ReceiveUpload(const ContainedDirectory& folder, const std::string& directory, const std::string& name,
                          const UploadKind& kind, std::size_t declared_bytes, std::size_t max_bytes,
                          const BodyReader& read, const std::function<void(const std::string& staged_path)>& check);

}  // namespace uphill::internal
