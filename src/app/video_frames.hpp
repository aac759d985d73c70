// One frame of a trial's video as an image file, for the page (the frame the technician clicks
// calibration points on, the strip of tracked frames), and a video's size and length.
#pragma once

#include <string>

namespace uphill {

struct VideoProbe {
  int width = 0, height = 0;
  double fps = 0;   // the container's nominal rate (0: unknown)
  long frames = 0;  // the container's frame count (0: unknown)
};

// Opens the video with OpenCV's FFmpeg backend. Throws InputError(label, "is not a video ...")
// for a file OpenCV cannot decode (an image, a text file, a cut-off upload).
VideoProbe ProbeVideo(const std::string& path, const std::string& label);

struct EncodedFrame {
  std::string bytes;         // the image file
  std::string content_type;  // "image/png" or "image/jpeg"
  VideoProbe video;
  int index = 0;             // the frame decoded
  double t = 0;              // its timestamp, s (the container's)
};

// Decodes frame `index` (0 = first; seeks, then reads) and encodes it losslessly as PNG (`jpeg`:
// JPEG at quality 92, ~10x smaller, for the strip). Throws InputError as ProbeVideo, and
// InputError("frame") when the video has no frame `index`.
EncodedFrame ReadVideoFrame(const std::string& path, const std::string& label, int index, bool jpeg = false);

}  // namespace uphill
