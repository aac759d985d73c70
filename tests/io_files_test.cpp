// Writing files safely (src/io/atomic_file.hpp, contained_directory.hpp, output_paths.hpp): only
// regular files are ever replaced, a failed write leaves the target as it was, a contained folder
// never follows a link at any level nor lets "..", "." or an absolute path out, and an output is
// never an input however it is spelled. Truth: the file system's own
// answer (lstat, the bytes) before and after each call.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/contained_directory.hpp"
#include "io/output_paths.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "file_test_support.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;

using uphill::testing::FreshFolder;
const auto Slurp = uphill::testing::ReadBytes;

TEST(AtomicFile, ReplacesARegularFileAndLeavesNoTemporary) {
  const fs::path dir = FreshFolder("replace");
  std::ofstream(dir / "a.txt") << "old";
  WriteFileAtomically((dir / "a.txt").string(), "new content\n");
  EXPECT_EQ(Slurp(dir / "a.txt"), "new content\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, NeverReplacesAFolderALinkAPipeOrADevice) {
  const fs::path dir = FreshFolder("obstacles");
  fs::create_directories(dir / "folder");
  std::ofstream(dir / "target") << "keep";
  fs::create_symlink(dir / "target", dir / "link");
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0644), 0);
  for (const char* name : {"folder", "link", "pipe"}) {
    try {
      WriteFileAtomically((dir / name).string(), "x");
      ADD_FAILURE() << name << " was replaced";
    } catch (const EnvironmentError& e) {
      EXPECT_NE(std::string(e.what()).find("not replaced"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_directory(fs::symlink_status(dir / "folder")));
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(dir / "pipe")));
  EXPECT_EQ(Slurp(dir / "target"), "keep");
  // A device node (the issue's /dev/full, which made a regular file of itself as root).
  EXPECT_THROW(WriteFileAtomically("/dev/full", "x"), EnvironmentError);
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 4);  // no temporaries
  fs::remove_all(dir);
}

// The contract "a failure at any step leaves the target exactly as before" (atomic_file.hpp),
// with the write made to fail once the target exists: the file size limit (RLIMIT_FSIZE, as a
// full disk would, and as root too) stops the temporary's write with EFBIG. Truth: the target's
// bytes before and after, and the folder's listing (no temporary left).
TEST(AtomicFile, AFailedWriteLeavesTheExistingTargetAsItWas) {
  const fs::path dir = FreshFolder("atomic-failed-write");
  const fs::path target = dir / "fit.json";
  const std::string old_bytes = "{\"old\": true}\n";
  WriteFileAtomically(target.string(), old_bytes);
  rlimit saved {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of killing
  rlimit small = saved;
  small.rlim_cur = 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  try {
    WriteFileAtomically(target.string(), std::string(64 * 1024, 'x'));
  } catch (const EnvironmentError& e) {
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(message.find(target.string()), std::string::npos) << "no failure, or not named: " << message;
  EXPECT_EQ(Slurp(target), old_bytes);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"fit.json"});
  fs::remove_all(dir);
}

TEST(AtomicFile, AMissingFolderIsNamed) {
  try {
    WriteFileAtomically("/nonexistent-uphill/x/out.json", "x");
    ADD_FAILURE();
  } catch (const EnvironmentError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(ContainedDirectory, ReadsAndWritesInsideAndRefusesLinksAtAnyLevel) {
  const fs::path root = FreshFolder("contained");
  const fs::path outside = FreshFolder("contained-outside");
  std::ofstream(outside / "secret") << "secret";
  fs::create_directories(root / "sub");
  std::ofstream(root / "sub" / "file") << "inside";
  fs::create_directory_symlink(outside, root / "linked-folder");
  fs::create_symlink(outside / "secret", root / "sub" / "linked-file");
  const ContainedDirectory dir = ContainedDirectory::Open(root.string());
  EXPECT_EQ(dir.ReadFile("sub/file", 100).value_or(""), "inside");
  EXPECT_FALSE(dir.ReadFile("sub/absent", 100).has_value());
  EXPECT_EQ(dir.KindOf("linked-folder"), ContainedDirectory::Kind::kLink);
  EXPECT_THROW(dir.ReadFile("linked-folder/secret", 100), EnvironmentError);
  EXPECT_THROW(dir.ReadFile("sub/linked-file", 100), EnvironmentError);
  EXPECT_THROW(dir.KindOf("linked-folder/secret"), EnvironmentError);
  EXPECT_THROW(dir.WriteFileAtomically("linked-folder/new", "x"), EnvironmentError);
  EXPECT_THROW(dir.WriteFileAtomically("sub/linked-file", "x"), EnvironmentError);
  EXPECT_THROW(dir.Subdirectory("linked-folder", true), EnvironmentError);
  EXPECT_THROW(dir.OpenForAppend("sub/linked-file"), EnvironmentError);
  for (const char* bad : {"../contained-outside/secret", "/etc/passwd", "sub/../sub/file", "./sub/file", "sub//file", ""})
    EXPECT_THROW(dir.ReadFile(bad, 100), InputError) << bad;
  EXPECT_EQ(Slurp(outside / "secret"), "secret");
  EXPECT_EQ(std::distance(fs::directory_iterator(outside), fs::directory_iterator()), 1);
  EXPECT_THROW(dir.ReadFile("sub/file", 3), EnvironmentError);  // over the size limit
  // Writing inside: atomic, and a staging folder comes and goes.
  dir.WriteFileAtomically("sub/new", "made");
  EXPECT_EQ(Slurp(root / "sub" / "new"), "made");
  ContainedDirectory staging = dir.MakeStagingDirectory(".stage-");
  staging.WriteFileAtomically("f", "staged");
  const ContainedDirectory target = dir.Subdirectory("made/deeper", true);
  staging.MoveFile("f", target, "f");
  ContainedDirectory::RemoveStaging(dir, std::move(staging));
  EXPECT_EQ(Slurp(root / "made" / "deeper" / "f"), "staged");
  for (const auto& e : fs::directory_iterator(root)) EXPECT_NE(e.path().filename().string().rfind(".stage-", 0), 0u);
  fs::remove_all(root);
  fs::remove_all(outside);
}

// Issue 11: `track --overlay` naming the input video (relative, "./", through a link) overwrote
// the recording. The truth is the file system's identity of the files (device and inode): every
// spelling of the input is refused, naming the flag and the input; other files are allowed.
TEST(OutputPaths, AnOutputIsNeverAnInputHoweverItIsSpelled) {
  const fs::path dir = FreshFolder("output-paths");
  fs::create_directories(dir / "sub");
  std::ofstream(dir / "clip.mp4") << "recording";
  fs::create_symlink(dir / "clip.mp4", dir / "link.mp4");
  fs::create_directory_symlink(dir, dir / "sub" / "up");
  fs::create_hard_link(dir / "clip.mp4", dir / "hard.mp4");
  const std::string base = dir.string();
  OutputPaths outputs;
  outputs.AddInput(base + "/clip.mp4", "the input video");
  for (const std::string& spelling : std::vector<std::string>{base + "/clip.mp4", base + "/./clip.mp4", base + "/sub/../clip.mp4",
                                      base + "/link.mp4", base + "/sub/up/clip.mp4", base + "/hard.mp4"}) {
    try {
      outputs.CheckFile(spelling, "--overlay");
      ADD_FAILURE() << spelling << " was allowed";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("--overlay " + spelling + ": is the input video", 0), 0u) << what;
    }
  }
  EXPECT_NO_THROW(outputs.CheckFile(base + "/overlay.mp4", "--overlay"));
  // Two outputs of one command that are the same file would overwrite each other.
  EXPECT_THROW(outputs.CheckFile(base + "/./overlay.mp4", "-o"), InputError);
  EXPECT_EQ(Slurp(dir / "clip.mp4"), "recording");
  fs::remove_all(dir);
}

// No output inside a folder the command keeps (the experiment's video cache), however the path is
// spelled (a link to it, "..", a missing folder below it). Truth: the identity of each folder above
// the output (device and inode).
TEST(OutputPaths, NoOutputInsideAnInputFolder) {
  const fs::path dir = FreshFolder("output-paths-folder");
  fs::create_directories(dir / "cache" / "video");
  fs::create_directory_symlink(dir / "cache", dir / "link");
  OutputPaths outputs;
  outputs.AddInputFolder((dir / "cache").string(), "the experiment's video cache");
  for (const fs::path& spelling : {dir / "cache" / "report.html", dir / "link" / "video" / "report.html",
                                   dir / "cache" / "video" / ".." / "fit.json", dir / "cache" / "new" / "fit.json"}) {
    try {
      outputs.CheckFile(spelling.string(), "-o");
      ADD_FAILURE() << spelling << " was allowed";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is inside the experiment's video cache"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(outputs.CheckFile((dir / "report.html").string(), "-o"));
  fs::remove_all(dir);
}

// Issue 11: as root, `-o /dev/full` replaced the device node with a regular file. Only a regular
// file is ever replaced; a file where a folder is needed is named. Truth: lstat before and after.
TEST(OutputPaths, OnlyRegularFilesAndFoldersThatCanBeMade) {
  const fs::path dir = FreshFolder("output-kinds");
  std::ofstream(dir / "afile") << "x";
  fs::create_directories(dir / "folder");
  OutputPaths outputs;
  EXPECT_THROW(outputs.CheckFile("/dev/full", "-o"), InputError);
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status("/dev/full")));
  EXPECT_THROW(outputs.CheckFile((dir / "folder").string(), "-o"), InputError);
  EXPECT_THROW(outputs.CheckFile((dir / "afile" / "x.csv").string(), "-o"), InputError);
  EXPECT_THROW(outputs.CheckFolder((dir / "afile").string(), "-o", {"report.md"}), InputError);
  // A missing folder is fine (it is made when the output is written), and made by CreateFolders.
  EXPECT_NO_THROW(outputs.CheckFile((dir / "new" / "deeper" / "x.csv").string(), "-o"));
  EXPECT_FALSE(fs::exists(dir / "new"));
  OutputPaths::CreateFolders((dir / "new" / "deeper").string());
  EXPECT_TRUE(fs::is_directory(dir / "new" / "deeper"));
  EXPECT_THROW(OutputPaths::CreateFolders((dir / "afile" / "below").string()), EnvironmentError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill
