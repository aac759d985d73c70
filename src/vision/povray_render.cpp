#include "vision/povray_render.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "internal/child_process.hpp"

namespace uphill {

namespace fs = std::filesystem;

PovrayRun RunPovray(const std::string& scene_text, cv::Size size, int frames, const std::string& work_dir,
                    const PovrayOptions& options) {
  if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("RunPovray: empty picture size");
  if (frames < 1) throw std::invalid_argument("RunPovray: frames must be >= 1");
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
    throw std::runtime_error("cannot run '" + options.program +
                             "': POV-Ray is needed for this footage (Debian package povray; scripts/install-deps.sh)");
  if (!status.ok())
    throw std::runtime_error("POV-Ray failed on " + (dir / "shot.pov").string() + " (exit " +
                             std::to_string(status.exit_code) + ", signal " + std::to_string(status.signal) +
                             "): " + internal::TailOfFile(log));
  // POV-Ray numbers animation frames with as many digits as the last one has; one frame: none.
  const int digits = static_cast<int>(std::to_string(frames).size());
  for (int f = 1; f <= frames; ++f) {
    std::string name = "shot.png";
    if (frames > 1) {
      char number[16];
      std::snprintf(number, sizeof number, "%0*d", digits, f);
      name = std::string("shot") + number + ".png";
    }
    const fs::path path = dir / name;
    cv::Mat picture = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (picture.empty() || picture.size() != size || picture.depth() != CV_16U || picture.channels() != 3)
      throw std::runtime_error(path.string() + ": POV-Ray wrote no 16-bit RGB picture of the requested size (" +
                               internal::TailOfFile(log) + ")");
    fs::remove(path);
    picture.convertTo(picture, CV_32FC3, 1.0 / 65535.0);
    run.pictures.push_back(picture);
  }
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
