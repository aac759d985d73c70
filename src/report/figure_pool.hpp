// FigurePool: figures (gnuplot_figure.hpp) drawn by up to N gnuplot processes at once, so that a
// report's figures use every core, and can be drawn while other work (tracking the videos) runs.
//
// Each figure is drawn by RenderFigure exactly as alone: its files are replaced atomically or not
// at all, and a figure already on disk as it would be drawn is reused. Figures are independent:
// one that fails (gnuplot's error, an image it leaves incomplete, something in the way) does not
// stop the others, which are all written; Wait then throws one EnvironmentError naming every
// failed figure with its script file and gnuplot's complaint.
//
// Threads: Render and Wait may be called from any thread. A figure submitted again (the same name
// and folder) with the same content is drawn once; with other content it is a bug (logic_error):
// two renderings of one name would race for its files.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "report/gnuplot_figure.hpp"

namespace uphill {

class FigurePool {
 public:
  // At most `processes` gnuplot processes at once (0: one per core).
  explicit FigurePool(unsigned processes = 0);
  // Waits for the figures submitted (their errors are dropped: call Wait to see them).
  ~FigurePool();
  FigurePool(const FigurePool&) = delete;
  FigurePool& operator=(const FigurePool&) = delete;

  // Queues the figure for `directory` (which must exist) and returns at once.
  void Render(GnuplotFigure figure, const std::string& directory);
  // Returns when every figure submitted so far is drawn; throws EnvironmentError naming each one
  // that failed since the last Wait (the others are written).
  void Wait();

 private:
  struct Job {
    GnuplotFigure figure;
    std::string directory;
  };
  void Work();

  unsigned processes_;
  std::mutex mutex_;
  std::condition_variable work_ready_, work_done_;
  std::deque<Job> queue_;
  std::size_t running_ = 0;
  bool stopping_ = false;
  std::vector<std::string> failures_;
  std::map<std::string, std::string> submitted_;  // folder/name -> data and script
  std::vector<std::thread> threads_;
};

}  // namespace uphill
