// OpenCV and FFmpeg print their own log lines to stderr (e.g. "[mov,mp4,… @ 0x…] moov atom not
// found" before a video is refused). uphill's promise is one line naming the problem, so those
// libraries are quietened before their first use; a user who wants their logs sets
// OPENCV_FFMPEG_LOGLEVEL or OPENCV_LOG_LEVEL, which are then left as they are.
#pragma once

namespace uphill {

// Idempotent and thread-safe; call before opening a video or reading an image.
void QuietVideoLibraryLogs();

}  // namespace uphill
