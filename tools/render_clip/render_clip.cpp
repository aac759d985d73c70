// render_clip: renders one condition of the POV-Ray test footage (src/vision/footage_clip.hpp,
// footage_conditions.hpp) into the clip cache, or finds it there, and prints where its files are
// and the commands of the user's path: calibrate the camera from the chessboard views, calibrate
// the scene from the apparatus points, track.
//
// Usage: render_clip CONDITION [--cache DIR] [--fresh] [--frames N]
//        render_clip --list
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#include "model/input_error.hpp"
#include "vision/footage_conditions.hpp"

namespace {

using namespace uphill;

struct Flags {
  std::string condition, cache;
  bool fresh = false, list = false;
  int frames = 0;
};

int Run(const Flags& f) {
  if (f.list) {
    for (const NamedFootage& n : RobustnessMatrix())
      std::printf("%-20s %s\n", n.condition.name.c_str(), n.description.c_str());
    std::printf("%-20s %s\n", "tiny", FootageByName("tiny").description.c_str());
    return 0;
  }
  NamedFootage named = FootageByName(f.condition);
  FootageCondition& c = named.condition;
  if (f.frames > 0) c.frames = f.frames;
  const std::string cache = f.cache.empty() ? FootageCacheRoot() : f.cache;
  FootageProgress progress;
  const bool tty = isatty(STDERR_FILENO);
  progress.report = [tty](const std::string& stage, int done, int total) {
    if (tty) std::fprintf(stderr, "\r%s %d/%d   ", stage.c_str(), done + 1, total);
  };
  const FootageFiles files = RenderFootage(c, cache, f.fresh, progress);
  if (tty) std::fprintf(stderr, "\n");
  std::printf("%s: %s\n", c.name.c_str(), named.description.c_str());
  std::printf("folder  %s\n", files.folder.c_str());
  std::printf("%s %.1f s wall, %.1f s CPU (%d POV-Ray runs, %d sub-frames)\n",
              files.from_cache ? "cached; rendered in" : "rendered in", files.render_wall_seconds,
              files.render_cpu_seconds, files.povray_runs, files.subframes);
  std::printf("video %s\ntruth %s\n", files.video.c_str(), files.truth_csv.c_str());
  std::printf("\nthe user's path:\n");
  std::string boards;
  if (!files.boards.empty()) {
    const std::string dir = files.boards.front().substr(0, files.boards.front().rfind('/'));
    boards = dir + "/board_*.png";
  }
  std::printf("  uphill calibrate camera %s --cols %d --rows %d --square %gmm -o cam.json\n", boards.c_str(),
              c.board_target.cols, c.board_target.rows, c.board_target.square * 1e3);
  std::printf("  uphill calibrate scene --camera cam.json --points %s --frame %s -o scene.json\n",
              files.points_csv.c_str(), files.first_frame.c_str());
  std::printf("  uphill track %s --camera cam.json --scene scene.json %s -o track.csv\n", files.video.c_str(),
              FootageSceneFlags(c).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"render_clip: POV-Ray test footage of the apparatus with exact ground truth"};
  Flags f;
  app.add_option("condition", f.condition, "condition name (--list shows them)");
  app.add_option("--cache", f.cache, "clip cache (default ${XDG_CACHE_HOME:-~/.cache}/uphill/clips)");
  app.add_flag("--fresh", f.fresh, "render again even if cached");
  app.add_option("--frames", f.frames, "render only this many frames (a different clip in the cache)");
  app.add_flag("--list", f.list, "list the conditions");
  CLI11_PARSE(app, argc, argv);
  if (f.condition.empty() && !f.list) {
    std::cerr << "render_clip: give a condition (render_clip --list)\n";
    return 2;
  }
  try {
    return Run(f);
  } catch (const uphill::InputError& e) {
    std::cerr << "render_clip: " << e.what() << "\n";
    return 2;
  } catch (const std::runtime_error& e) {
    // The environment: povray or ffmpeg missing or failing, a cache folder not writable.
    std::cerr << "render_clip: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "render_clip: " << e.what() << "\n";
    return 1;
  }
}
