// OutputPaths: "may I write this output?", asked for every output of a command before the
// command does any work, so that a mistyped flag costs nothing and never destroys anything.
//
// Rules (each refusal is an InputError naming the flag and the path, e.g.
// "--overlay run.mp4: is the input video run.mp4 …", exit status 2):
//   - An output never replaces an input: the same file however it is spelled (relative, "./",
//     through a symbolic link or a folder link, a hard link) — compared by device and inode.
//   - Only a regular file is ever replaced: a folder, a device (/dev/full), a pipe, a socket or a
//     symbolic link at an output's name is refused and left alone.
//   - The output's folder must be writable: the nearest folder on its path that exists must be a
//     folder (not a file) that this user can write; missing folders below it are created when
//     the output is written (CreateFolders), never earlier.
// Outputs written into a folder are checked by name (CheckFolder with the files the command
// writes there), so `report EXP -o EXP` cannot replace EXP's own files.
//
// The writers check again at the moment they write (io/atomic_file.hpp refuses non-regular
// targets): these checks are the early, friendly ones.
#pragma once

#include <string>
#include <sys/types.h>
#include <utility>
#include <vector>

namespace uphill {

class OutputPaths {
 public:
  // A file the command reads, with what to call it in messages ("the input video"). Absent
  // paths and "-" (stdin) are ignored: their readers say what is wrong with them.
  void AddInput(const std::string& path, const std::string& what);
  // A folder the command reads or keeps (a cache): no output is written inside it, however the
  // path is spelled (each folder above the output is compared by device and inode). Absent
  // folders are ignored.
  void AddInputFolder(const std::string& path, const std::string& what);

  // Checks the output file `path` given by `flag`, and that no earlier checked output is the same
  // path (two outputs of one command would overwrite each other). Throws InputError.
  void CheckFile(const std::string& path, const std::string& flag);
  // Checks the output folder `path` (created if needed) and each of `files` in it. Throws
  // InputError.
  void CheckFolder(const std::string& path, const std::string& flag, const std::vector<std::string>& files);

  // Creates the missing folders of `folder` (mode 0755). Throws EnvironmentError naming it.
  static void CreateFolders(const std::string& folder);

 private:
  struct Input {
    dev_t device;
    ino_t inode;
    std::string path, what;
  };
  void CheckWritableFolder(const std::string& folder, const std::string& context) const;
  // The entry of `inputs` that is the file or folder at `path` (followed), or nullptr.
  static const Input* SameFile(const std::vector<Input>& inputs, const std::string& path);
  void RefuseInsideInputFolder(const std::string& path, const std::string& context) const;
  std::vector<Input> inputs_;
  std::vector<Input> input_folders_;
  std::vector<std::pair<std::string, std::string>> outputs_;  // resolved path, flag
};

}  // namespace uphill
