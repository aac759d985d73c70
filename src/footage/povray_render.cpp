#include "footage/povray_render.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "internal/child_process.hpp"
#include "internal/content_key.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {

namespace fs = std::filesystem;

namespace {

// The picture cache's folder for a render (empty without a cache): keyed by everything that
// changes its pixels (not the thread count: no jitter).
fs::path CacheFolder(const std::string& scene_text, cv::Size size, int frames, const PovrayOptions& options) {
  if (options.picture_cache.empty()) return {};
  char quality[80];
  std::snprintf(quality, sizeof quality, "%dx%d %d frames, aa %.6g depth %d\n", size.width, size.height, frames,
                options.antialias_threshold, options.antialias_depth);
  return fs::path(options.picture_cache) / internal::ContentKey(quality + scene_text);
}

}  // namespace

bool PovrayPicturesCached(const std::string& scene_text, cv::Size size, int frames, const PovrayOptions& options) {
  const fs::path cached = CacheFolder(scene_text, size, frames, options);
  return !cached.empty() && fs::exists(cached / "complete");
}

PovrayRun RunPovray(const std::string& scene_text, cv::Size size, int frames, const std::string& work_dir,
                    const PovrayOptions& options) {
  if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("RunPovray: empty picture size");
  if (frames < 1) throw std::invalid_argument("RunPovray: frames must be >= 1");
  const fs::path cached = CacheFolder(scene_text, size, frames, options);
  const int digits = static_cast<int>(std::to_string(frames).size());
  auto picture_name = [&](int f) {
    // POV-Ray numbers animation frames with as many digits as the last one has; one frame: none.
    if (frames == 1) return std::string("shot.png");
    char number[16];
    std::snprintf(number, sizeof number, "%0*d", digits, f);
    return std::string("shot") + number + ".png";
  };
  auto read = [&](const fs::path& folder, PovrayRun* run, const std::string& log) {
    for (int f = 1; f <= frames; ++f) {
      const fs::path path = folder / picture_name(f);
      cv::Mat picture = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
      if (picture.empty() || picture.size() != size || picture.depth() != CV_16U || picture.channels() != 3)
        throw std::runtime_error(path.string() + ": POV-Ray wrote no 16-bit RGB picture of the requested size (" +
                                 internal::TailOfFile(log) + ")");
      picture.convertTo(picture, CV_32FC3, 1.0 / 65535.0);
      run->pictures.push_back(picture);
    }
  };
  if (PovrayPicturesCached(scene_text, size, frames, options)) {
    PovrayRun run;
    run.cached = true;
    read(cached, &run, "");
    return run;
  }
  const fs::path dir = fs::absolute(work_dir);
  fs::create_directories(dir);
  {
    std::ofstream out(dir / "shot.pov", std::ios::trunc);
    out << scene_text;
    if (!out) throw std::runtime_error((dir / "shot.pov").string() + ": cannot write the POV-Ray scene");
  }
  const std::string log = (dir / "shot.log").string();
  fs::remove(log);
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "+A%.4f", options.antialias_threshold);
  std::vector<std::string> argv = {options.program,
                                   "-D",
                                   "+Ishot.pov",
                                   "+Oshot.png",
                                   "+W" + std::to_string(size.width),
                                   "+H" + std::to_string(size.height),
                                   "+FN16",
                                   "File_Gamma=1.0",
                                   "Output_Alpha=off",
                                   threshold,
                                   "+AM2",
                                   "+R" + std::to_string(options.antialias_depth),
                                   "-J",
                                   "+WT" + std::to_string(options.threads),
                                   "+KFI1",
                                   "+KFF" + std::to_string(frames)};
  const auto start = std::chrono::steady_clock::now();
  const internal::ChildStatus status = internal::RunChild(argv, dir.string(), log);
  PovrayRun run;
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.cpu_seconds = status.cpu_seconds;
  if (!status.started)
    throw EnvironmentError("cannot run '" + options.program +
                           "': POV-Ray is needed for this footage (Debian package povray; scripts/install-deps.sh)");
  if (!status.ok())
    throw std::runtime_error("POV-Ray failed on " + (dir / "shot.pov").string() + " (exit " +
                             std::to_string(status.exit_code) + ", signal " + std::to_string(status.signal) +
                             "): " + internal::TailOfFile(log));
  read(dir, &run, log);
  if (!cached.empty()) {
    // Into the cache under a private name, then renamed: a folder there is complete.
    std::error_code ec;
    const fs::path partial = cached.string() + ".partial-" + std::to_string(getpid()) + "-" + dir.filename().string();
    fs::create_directories(partial, ec);
    for (int f = 1; f <= frames && !ec; ++f) fs::rename(dir / picture_name(f), partial / picture_name(f), ec);
    if (!ec) std::ofstream(partial / "complete") << "";
    if (!ec) fs::rename(partial, cached, ec);
    if (ec) fs::remove_all(partial, ec);  // another process cached it first, or the disk is full
  }
  for (int f = 1; f <= frames; ++f) fs::remove(dir / picture_name(f));
  return run;
}

bool PovrayAvailable(const std::string& program) {
  const std::string log = (fs::temp_directory_path() / "uphill-povray-version.log").string();
  const internal::ChildStatus status = internal::RunChild({program, "--version"}, "", log);
  std::error_code ec;
  fs::remove(log, ec);
  return status.ok();
}

}  // namespace uphill
