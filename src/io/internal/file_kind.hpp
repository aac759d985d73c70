// Internal to the io layer: what kind of thing is at a path, in the words of an error message
// ("a folder", "a device", ...), for the writers that refuse anything but a regular file.
#pragma once

#include <sys/stat.h>

#include <string>

namespace uphill::internal {

// "a folder", "a symbolic link", "a device", "a named pipe", "a socket"; "not a regular file" for
// anything else that is not a regular file; "" for a regular file.
inline std::string FileKindName(mode_t mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISFIFO(mode)) return "a named pipe";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace uphill::internal
