// render_clip: renders one condition of the POV-Ray test footage (src/footage/footage_clip.hpp,
// footage_conditions.hpp) into the clip cache, or finds it there, and prints where its files are
// and the commands of the user's path: calibrate the camera from the chessboard views, calibrate
// the scene from the apparatus points, track.
//
// Usage: render_clip CONDITION [--cache DIR] [--fresh] [--frames N] [--processes N] [--threads N]
//        render_clip CONDITION --plan [--cache DIR] [--frames N]
//        render_clip --list
// --plan renders nothing: it prints what POV-Ray would be asked for (sub-frames per frame, those
// already in the picture cache apart), to estimate a render's time from a sample's.
// --processes 1 --threads 1 keeps POV-Ray to one core of a shared machine (the clip is the same).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#include "model/input_error.hpp"
#include "footage/footage_conditions.hpp"

namespace {

using namespace uphill;

struct Flags {
  std::string condition, cache;
  bool fresh = false, list = false, plan = false;
  int frames = 0;
  int processes = 6, threads = 2;
};

void PrintPlan(const FootageCondition& c, const FootageWork& w) {
  std::printf("%s: %d frames %dx%d%s\n", c.name.c_str(), c.frames, c.camera.camera.width, c.camera.camera.height,
              w.clip_cached ? " (the clip is cached: nothing to render)" : "");
  std::printf("chessboard views: %s\n", w.boards_cached ? "cached" : (std::to_string(c.boards) + " to render").c_str());
  std::printf("static pictures: %d, %d to render (%.2f Mpx)\n", w.static_pictures, w.static_to_render,
              w.static_pixels_to_render * 1e-6);
  std::printf("body windows: %d sub-frames, %d to render in %d POV-Ray runs (%.2f Mpx)\n", w.subframes,
              w.subframes_to_render, w.runs_to_render, w.pixels_to_render * 1e-6);
  std::printf("frame  sub-frames  to-render  Mpx-to-render\n");
  for (const FootageFrameWork& f : w.frames)
    std::printf("%5d  %10d  %9d  %13.3f\n", f.frame, f.subframes, f.subframes_to_render, f.pixels_to_render * 1e-6);
}

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
  c.povray_processes = f.processes;
  c.povray.threads = f.threads;
  const std::string cache = f.cache.empty() ? FootageCacheRoot() : f.cache;
  if (f.plan) {
    PrintPlan(c, PlanFootage(c, cache));
    return 0;
  }
  FootageProgress progress;
  const bool tty = isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  progress.report = [tty, start](const std::string& stage, int done, int total) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // On a terminal one line that updates; into a log a line per step, with the time so far.
    std::fprintf(stderr, tty ? "\r%s %d/%d (%.0f s)   " : "%s %d/%d (%.0f s)\n", stage.c_str(), done + 1, total, s);
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
  app.add_option("--processes", f.processes, "POV-Ray programs at once (default 6)")->check(CLI::Range(1, 64));
  app.add_option("--threads", f.threads, "threads of each POV-Ray program (default 2)")->check(CLI::Range(1, 64));
  app.add_flag("--plan", f.plan, "print what POV-Ray would render (sub-frames per frame), render nothing");
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
