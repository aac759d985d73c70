// One frame of a trial's video as an image file, for the page (the frame the technician clicks
// calibration points on, the strip of tracked frames), and a video's size and length.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "vision/decode_limits.hpp"

namespace uphill {

struct VideoProbe {
  int width = 0, height = 0;
  double fps = 0;   // the container's nominal rate (0: unknown)
  long frames = 0;  // the container's frame count (0: unknown)
};

// Opens the video with OpenCV's FFmpeg backend. Throws InputError(label, "is not a video ...")
// for a file OpenCV cannot decode (an image, a text file, a cut-off upload), InputError(label)
// for frames of more pixels than uphill decodes (vision/decode_limits.hpp), read from the
// container before any frame is decoded, and RequireVideoFrames's error for a still picture
// (where the container does not state its frame count, the first two frames are decoded).
VideoProbe ProbeVideo(const std::string& path, const std::string& label);

// A recording has at least two frames. FFmpeg opens a still picture (a PNG or JPEG, whatever its
// name) as a video of one frame, which would be tracked as a "video" of one position: throws
// InputError(label, "is a still picture, not a video: ...") for fewer than kMinVideoFrames.
inline constexpr long kMinVideoFrames = 2;
void RequireVideoFrames(long frames, const std::string& label);

struct EncodedFrame {
  std::string bytes;         // the image file
  std::string content_type;  // "image/png" or "image/jpeg"
  VideoProbe video;
  int index = 0;             // the frame decoded
  double t = 0;              // its timestamp, s (the container's)
};

// Decodes frame `index` (0 = first; seeks, then reads) and encodes it losslessly as PNG (`jpeg`:
// JPEG at quality 92, ~10x smaller, for the strip). Throws InputError as ProbeVideo, and
// InputError("frame") when the video has no frame `index`. With a `budget`, the decode first
// leases FrameDecodeBytes of it, waiting at most `wait` (DecodeBusy when it does not fit).
EncodedFrame ReadVideoFrame(const std::string& path, const std::string& label, int index, bool jpeg = false,
                            DecodeBudget* budget = nullptr,
                            std::chrono::milliseconds wait = std::chrono::milliseconds(0));

// The bytes a frame of `video` holds while it is read and encoded: the decoded BGR frame and its
// encoded copy, each counted at 3 bytes a pixel.
std::size_t FrameDecodeBytes(const VideoProbe& video);

}  // namespace uphill
