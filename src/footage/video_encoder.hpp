// VideoEncoder: writes 8-bit BGR frames as a video file with the `ffmpeg` program (Debian package
// ffmpeg), fed raw frames on its standard input.
//
// Why ffmpeg and not cv::VideoWriter: a phone's encoder runs at a set bit rate with a GOP of
// about a second, and its compression artefacts depend on both; OpenCV's writer chooses the bit
// rate itself and cannot set it, the GOP or the encoder's preset, and writes no H.265 through
// Debian's OpenCV 4.6. ffmpeg sets all of them (libx264 / libx265, constrained to the target bit
// rate; FFV1 for lossless) and writes exact constant-rate timestamps.
//
// Codecs: kH264 (libx264, High profile, yuv420p, .mp4), kH265 (libx265, yuv420p, tagged hvc1,
// .mp4), kFfv1 (lossless, bgr0, .mkv). Colour: ffmpeg's default BGR -> YUV conversion (BT.601,
// limited range), which OpenCV's FFmpeg reader inverts.
// The file is written under a temporary name and renamed when complete (never a half-written
// clip under the final name).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace uphill {

enum class VideoCodec { kH264, kH265, kFfv1 };

// "h264", "h265", "ffv1".
std::string CodecName(VideoCodec codec);

// A phone's bit rate for the codec at this size and rate, bits/s: H.264 about 0.27 bit per pixel
// per frame at 30 fps (16 Mbit/s at 1080p30, 8 at 720p30), 0.2 at 60 fps; H.265 at 60 % of that.
double PhoneBitRate(VideoCodec codec, cv::Size size, double fps);

struct VideoEncoderSettings {
  VideoCodec codec = VideoCodec::kH264;
  double fps = 30;
  double bit_rate = 0;        // bits/s; 0: PhoneBitRate (ignored by FFV1)
  double gop_seconds = 1.0;   // key frame interval
  std::string program = "ffmpeg";
};

class VideoEncoder {
 public:
  // Starts ffmpeg. Throws EnvironmentError when it cannot be started (not installed).
  VideoEncoder(const std::string& path, cv::Size size, const VideoEncoderSettings& settings);
  ~VideoEncoder();  // an unfinished file is removed
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // Throws std::runtime_error (with ffmpeg's message) when ffmpeg stopped reading.
  void Write(const cv::Mat& frame_bgr8);
  // Waits for ffmpeg and renames the file into place. Throws std::runtime_error on failure.
  void Finish();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill
