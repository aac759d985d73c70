#include "report/figure_pool.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "model/environment_error.hpp"

namespace uphill {

FigurePool::FigurePool(unsigned processes)
    : processes_(processes ? processes : std::max(1u, std::thread::hardware_concurrency())) {}

FigurePool::~FigurePool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  work_ready_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void FigurePool::Render(GnuplotFigure figure, const std::string& directory) {
  const std::string key = (std::filesystem::path(directory) / figure.name).lexically_normal().string();
  std::string content = figure.title + '\0' + figure.data + '\0' + figure.plot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto [it, inserted] = submitted_.emplace(key, std::move(content));
    if (!inserted) {
      if (it->second == figure.title + '\0' + figure.data + '\0' + figure.plot) return;
      throw std::logic_error("FigurePool: figure " + key + " submitted twice with different content");
    }
    queue_.push_back({std::move(figure), directory});
    // Threads are started as work arrives, up to the bound: a pool that draws one figure runs one.
    if (threads_.size() < processes_ && threads_.size() < queue_.size() + running_)
      threads_.emplace_back([this] { Work(); });
  }
  work_ready_.notify_one();
}

void FigurePool::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_ready_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, nothing left
    Job job = std::move(queue_.front());
    queue_.pop_front();
    ++running_;
    lock.unlock();
    std::string failure;
    try {
      RenderFigure(job.figure, job.directory);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    lock.lock();
    --running_;
    if (!failure.empty()) failures_.push_back(std::move(failure));
    if (queue_.empty() && running_ == 0) work_done_.notify_all();
  }
}

void FigurePool::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  work_done_.wait(lock, [this] { return queue_.empty() && running_ == 0; });
  if (failures_.empty()) return;
  // Sorted, the same report whatever order they ran in; a message met by several figures (a
  // missing gnuplot names no figure) is given once, with how many figures it stopped.
  std::map<std::string, std::size_t> failures;
  for (std::string& f : failures_) ++failures[std::move(f)];
  const std::size_t failed = failures_.size();
  failures_.clear();
  std::string message = failed == 1 ? "" : std::to_string(failed) + " figures failed: ";
  bool first = true;
  for (const auto& [text, count] : failures) {
    message += (first ? "" : "; ") + text;
    if (count > 1) message += " (" + std::to_string(count) + " figures)";
    first = false;
  }
  throw EnvironmentError(message);
}

}  // namespace uphill
