#include "model/solver_logs.hpp"

#include <glog/logging.h>

#include <cstdlib>
#include <mutex>

namespace uphill {

void QuietSolverLogs() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (std::getenv("GLOG_minloglevel") == nullptr) FLAGS_minloglevel = google::GLOG_FATAL;
  });
}

}  // namespace uphill
