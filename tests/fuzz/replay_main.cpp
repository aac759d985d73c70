// The ordinary-build entry point of a fuzz target: feeds every committed seed file (the
// arguments: files, or folders whose regular files are read in name order) to the target's
// LLVMFuzzerTestOneInput, as libFuzzer does on replay. The target itself checks the contract
// (only InputError escapes, accepted values are finite, …) and aborts on a breach; in the
// sanitizer build ASan and UBSan watch every input too. So each seed of tests/fuzz/corpus/ is
// a regression test in every build, not only in the clang fuzz build of scripts/fuzz.sh.
// Exit status: 0 when every seed ran, 1 when an argument names nothing readable or there were
// no seeds at all (a test that ran nothing must not pass).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

bool ReadFile(const fs::path& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> seeds;
  for (int i = 1; i < argc; ++i) {
    const fs::path arg = argv[i];
    std::error_code ec;
    if (fs::is_directory(arg, ec)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(arg, ec))
        if (entry.is_regular_file()) files.push_back(entry.path());
      std::sort(files.begin(), files.end());
      seeds.insert(seeds.end(), files.begin(), files.end());
    } else if (fs::is_regular_file(arg, ec)) {
      seeds.push_back(arg);
    } else {
      std::fprintf(stderr, "%s: no such seed file or folder\n", arg.c_str());
      return 1;
    }
  }
  if (seeds.empty()) {
    std::fprintf(stderr, "no seeds given: nothing was replayed\n");
    return 1;
  }
  std::string bytes;
  for (const fs::path& seed : seeds) {
    if (!ReadFile(seed, bytes)) {
      std::fprintf(stderr, "%s: cannot read\n", seed.c_str());
      return 1;
    }
    std::fprintf(stderr, "%s\n", seed.filename().c_str());  // names the seed a crash stops at
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("replayed %zu seeds\n", seeds.size());
  return 0;
}
