#include "io/output_paths.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "internal/file_kind.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;

// "out/x.csv" → "out"; "x.csv" → "."
std::string FolderOf(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() && !p.parent_path().empty() ? p.parent_path().string() : ".";
}

}  // namespace

void OutputPaths::AddInput(const std::string& path, const std::string& what) {
  if (path.empty() || path == "-") return;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  inputs_.push_back({st.st_dev, st.st_ino, path, what});
}

const OutputPaths::Input* OutputPaths::SameFile(const std::vector<Input>& inputs, const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return nullptr;
  for (const Input& in : inputs)
    if (in.device == st.st_dev && in.inode == st.st_ino) return &in;
  return nullptr;
}

void OutputPaths::AddInputFolder(const std::string& path, const std::string& what) {
  struct stat st {};
  if (path.empty() || ::stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return;
  input_folders_.push_back({st.st_dev, st.st_ino, path, what});
}

void OutputPaths::RefuseInsideInputFolder(const std::string& path, const std::string& context) const {
  if (input_folders_.empty()) return;
  std::error_code ec;
  fs::path folder = fs::weakly_canonical(fs::absolute(FolderOf(path)), ec);
  if (ec) return;
  for (;;) {
    if (const Input* in = SameFile(input_folders_, folder.string()))
      throw InputError(context, "is inside " + in->what + " " + in->path +
                                    ": an output is never written among the inputs; write elsewhere");
    if (!folder.has_parent_path() || folder.parent_path() == folder) return;
    folder = folder.parent_path();
  }
}

void OutputPaths::CheckWritableFolder(const std::string& folder, const std::string& context) const {
  // The nearest folder on the path that exists: it must be a folder this user can write.
  fs::path existing = fs::path(folder);
  for (;;) {
    struct stat st {};
    if (::stat(existing.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        throw InputError(context, existing.string() + " is a file, not a folder");
      if (::access(existing.c_str(), W_OK | X_OK) != 0)
        throw InputError(context, "cannot write into the folder " + existing.string() + " (" + std::strerror(errno) + ")");
      return;
    }
    if (errno != ENOENT && errno != ENOTDIR)
      throw InputError(context, "cannot reach the folder " + existing.string() + " (" + std::strerror(errno) + ")");
    // Missing, or a file somewhere above it: look one level up (to name that file, or to find
    // the folder the missing ones will be created in).
    fs::path parent = existing.parent_path();
    if (parent.empty()) parent = ".";
    if (parent == existing) return;
    existing = parent;
  }
}

void OutputPaths::CheckFile(const std::string& path, const std::string& flag) {
  const std::string context = flag + " " + path;
  if (path.empty()) throw InputError(flag, "is empty (give a file name)");
  if (path.back() == '/') throw InputError(context, "names a folder; give a file name");
  if (const Input* in = SameFile(inputs_, path))
    throw InputError(context, "is " + in->what + " " + in->path +
                                  " (the same file): an output never replaces an input; write elsewhere");
  RefuseInsideInputFolder(path, context);
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(context, "is " + internal::FileKindName(st.st_mode) + ", not a regular file: never replaced (write to a file)");
  CheckWritableFolder(FolderOf(path), context);
  std::error_code ec;
  const std::string resolved = fs::weakly_canonical(fs::absolute(path), ec).string();
  for (const auto& [other, other_flag] : outputs_)
    if (other == resolved)
      throw InputError(context, "is also the output of " + other_flag + ": two outputs would overwrite each other");
  outputs_.emplace_back(resolved, flag);
}

void OutputPaths::CheckFolder(const std::string& path, const std::string& flag,
                              const std::vector<std::string>& files) {
  const std::string context = flag + " " + path;
  if (path.empty()) throw InputError(flag, "is empty (give a folder)");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) throw InputError(context, "is a file, not a folder");
    if (::access(path.c_str(), W_OK | X_OK) != 0)
      throw InputError(context, std::string("cannot write into the folder (") + std::strerror(errno) + ")");
  } else {
    CheckWritableFolder(path, context);
  }
  for (const std::string& name : files) CheckFile((fs::path(path) / name).string(), flag);
}

void OutputPaths::CreateFolders(const std::string& folder) {
  if (folder.empty() || folder == ".") return;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw EnvironmentError(folder + ": cannot create the folder: " + ec.message());
}

}  // namespace uphill
