#include "footage/video_encoder.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "internal/child_process.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {

namespace fs = std::filesystem;

std::string CodecName(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264: return "h264";
    case VideoCodec::kH265: return "h265";
    case VideoCodec::kFfv1: return "ffv1";
  }
  return "?";
}

double PhoneBitRate(VideoCodec codec, cv::Size size, double fps) {
  const double bits_per_pixel = fps > 45 ? 0.20 : 0.27;
  const double h264 = bits_per_pixel * size.width * size.height * fps;
  return codec == VideoCodec::kH265 ? 0.6 * h264 : h264;
}

struct VideoEncoder::Impl {
  std::string path, temporary, log;
  cv::Size size;
  std::unique_ptr<internal::ChildInput> child;
  bool finished = false;
};

VideoEncoder::VideoEncoder(const std::string& path, cv::Size size, const VideoEncoderSettings& s)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.size = size;
  const fs::path p(path);
  m.temporary = (p.parent_path() / (p.stem().string() + ".partial" + p.extension().string())).string();
  m.log = (p.parent_path() / (p.stem().string() + ".ffmpeg.log")).string();
  fs::remove(m.log);
  char rate[32], size_text[32];
  std::snprintf(rate, sizeof rate, "%.6g", s.fps);
  std::snprintf(size_text, sizeof size_text, "%dx%d", size.width, size.height);
  std::vector<std::string> argv = {s.program, "-hide_banner", "-nostats", "-loglevel", "error", "-y",
                                   "-f", "rawvideo", "-pix_fmt", "bgr24", "-s", size_text, "-framerate", rate,
                                   "-i", "-"};
  const double bit_rate = s.bit_rate > 0 ? s.bit_rate : PhoneBitRate(s.codec, size, s.fps);
  const std::string b = std::to_string(static_cast<long>(std::lround(bit_rate)));
  const std::string max = std::to_string(static_cast<long>(std::lround(1.5 * bit_rate)));
  const std::string buf = std::to_string(static_cast<long>(std::lround(2 * bit_rate)));
  const std::string gop = std::to_string(std::max(1L, std::lround(s.gop_seconds * s.fps)));
  switch (s.codec) {
    case VideoCodec::kH264:
      // One thread: x264's frame threads under a bit rate and VBV make each run's pictures differ
      // by a few levels (measured: three encodes of one clip decoded to three different clips),
      // and a draw of the random benchmark must be the same clip on every machine and run.
      argv.insert(argv.end(), {"-c:v", "libx264", "-threads", "1", "-preset", "medium", "-profile:v", "high", "-b:v", b,
                               "-maxrate", max, "-bufsize", buf, "-g", gop, "-pix_fmt", "yuv420p"});
      break;
    case VideoCodec::kH265:
      argv.insert(argv.end(), {"-c:v", "libx265", "-preset", "medium", "-x265-params", "log-level=error", "-b:v", b,
                               "-maxrate", max, "-bufsize", buf, "-g", gop, "-pix_fmt", "yuv420p", "-tag:v",
                               "hvc1"});
      break;
    case VideoCodec::kFfv1:
      argv.insert(argv.end(), {"-c:v", "ffv1", "-level", "3", "-g", "1", "-pix_fmt", "bgr0"});
      break;
  }
  argv.push_back(m.temporary);
  m.child = std::make_unique<internal::ChildInput>(argv, m.log);
  if (!m.child->started())
    throw EnvironmentError("cannot run '" + s.program +
                           "': the footage is encoded with ffmpeg (Debian package ffmpeg; scripts/install-deps.sh)");
}

VideoEncoder::~VideoEncoder() {
  if (impl_ && !impl_->finished) {
    impl_->child.reset();
    std::error_code ec;
    fs::remove(impl_->temporary, ec);
  }
}

void VideoEncoder::Write(const cv::Mat& frame) {
  Impl& m = *impl_;
  if (frame.type() != CV_8UC3 || frame.size() != m.size)
    throw std::invalid_argument("VideoEncoder::Write: frame of another size or type than the video's");
  const cv::Mat c = frame.isContinuous() ? frame : frame.clone();
  if (!m.child->Write(c.data, c.total() * c.elemSize()))
    throw std::runtime_error(m.path + ": ffmpeg stopped reading frames: " + internal::TailOfFile(m.log));
}

void VideoEncoder::Finish() {
  Impl& m = *impl_;
  const internal::ChildStatus status = m.child->Finish();
  if (!status.ok())
    throw std::runtime_error(m.path + ": ffmpeg failed (exit " + std::to_string(status.exit_code) +
                             "): " + internal::TailOfFile(m.log));
  fs::rename(m.temporary, m.path);
  m.finished = true;
  std::error_code ec;
  fs::remove(m.log, ec);
}

}  // namespace uphill
