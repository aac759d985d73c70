#include "vision/library_logs.hpp"

#include <cstdlib>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>

namespace uphill {

void QuietVideoLibraryLogs() {
  static std::once_flag once;
  std::call_once(once, [] {
    // Read by OpenCV's FFmpeg backend when it first initialises FFmpeg: AV_LOG_QUIET (-8).
    ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
    if (std::getenv("OPENCV_LOG_LEVEL") == nullptr)
      cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  });
}

}  // namespace uphill
