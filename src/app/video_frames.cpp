#include "app/video_frames.hpp"

#include <optional>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "model/input_error.hpp"
#include "vision/library_logs.hpp"

namespace uphill {
namespace {

cv::VideoCapture OpenCapture(const std::string& path) {
  QuietVideoLibraryLogs();
  cv::VideoCapture capture;
  try {
    capture.open(path, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
  }
  return capture;
}

bool Readable(cv::VideoCapture& capture) {
  return capture.isOpened() && capture.get(cv::CAP_PROP_FRAME_WIDTH) > 0;
}

// The frame size the container declares, before a frame is decoded.
void CheckFrameSize(cv::VideoCapture& capture, const std::string& label) {
  CheckPixelCount(static_cast<std::int64_t>(capture.get(cv::CAP_PROP_FRAME_WIDTH)),
                  static_cast<std::int64_t>(capture.get(cv::CAP_PROP_FRAME_HEIGHT)), label, "a video with frames");
}

cv::VideoCapture Open(const std::string& path, const std::string& label) {
  cv::VideoCapture capture = OpenCapture(path);
  if (!Readable(capture))
    throw InputError(label, "is not a video that OpenCV/FFmpeg can read (an image, another file, or a cut-off copy?)");
  CheckFrameSize(capture, label);
  return capture;
}

VideoProbe ProbeOf(cv::VideoCapture& capture) {
  VideoProbe p;
  p.width = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_WIDTH));
  p.height = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_HEIGHT));
  p.fps = capture.get(cv::CAP_PROP_FPS);
  p.frames = static_cast<long>(capture.get(cv::CAP_PROP_FRAME_COUNT));
  if (!(p.fps > 0 && p.fps < 1e4)) p.fps = 0;
  if (p.frames < 0) p.frames = 0;
  return p;
}

}  // namespace

VideoProbe ProbeVideo(const std::string& path, const std::string& label) {
  cv::VideoCapture capture = Open(path, label);
  const VideoProbe probe = ProbeOf(capture);
  long frames = probe.frames;
  if (frames < kMinVideoFrames) {  // unknown or too few: count what decodes
    frames = 0;
    cv::Mat frame;
    try {
      while (frames < kMinVideoFrames && capture.read(frame)) ++frames;
    } catch (const cv::Exception&) {
    }
  }
  RequireVideoFrames(frames, label);
  return probe;
}

void RequireVideoFrames(long frames, const std::string& label) {
  if (frames < kMinVideoFrames)
    throw InputError(label, "is a still picture, not a video: it holds " + std::to_string(frames) + " frame" +
                                (frames == 1 ? "" : "s") + " (a recording has at least " +
                                std::to_string(kMinVideoFrames) + ")");
}

std::size_t FrameDecodeBytes(const VideoProbe& video) {
  return static_cast<std::size_t>(video.width) * static_cast<std::size_t>(video.height) * 6;
}

EncodedFrame ReadVideoFrame(const std::string& path, const std::string& label, int index, bool jpeg,
                            DecodeBudget* budget, std::chrono::milliseconds wait) {
  if (index < 0) throw InputError("frame", "must be >= 0");
  cv::VideoCapture capture = Open(path, label);
  EncodedFrame out;
  out.video = ProbeOf(capture);
  if (out.video.frames > 0 && index >= out.video.frames)
    throw InputError("frame", "the video has " + std::to_string(out.video.frames) + " frames (0 to " +
                                  std::to_string(out.video.frames - 1) + "): no frame " + std::to_string(index));
  std::optional<DecodeBudget::Lease> lease;
  if (budget) lease.emplace(budget->Acquire(FrameDecodeBytes(out.video), wait, label));
  // Seeking in FFmpeg's H.264 lands on a key frame and decodes forward to the frame asked for.
  if (index > 0) capture.set(cv::CAP_PROP_POS_FRAMES, index);
  cv::Mat frame;
  bool ok = false;
  try {
    ok = capture.read(frame);
  } catch (const cv::Exception&) {
  }
  if (!ok || frame.empty()) throw InputError("frame", "frame " + std::to_string(index) + " of " + label + " cannot be decoded");
  out.index = index;
  out.t = capture.get(cv::CAP_PROP_POS_MSEC) / 1000;
  std::vector<unsigned char> bytes;
  if (jpeg) cv::imencode(".jpg", frame, bytes, {cv::IMWRITE_JPEG_QUALITY, 92});
  else cv::imencode(".png", frame, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1});
  out.bytes.assign(bytes.begin(), bytes.end());
  out.content_type = jpeg ? "image/jpeg" : "image/png";
  return out;
}

}  // namespace uphill
