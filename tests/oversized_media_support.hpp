// Small files that declare huge pictures, for the tests of the pixel limit
// (vision/decode_limits.hpp): a PNG and an MJPEG AVI encoded by OpenCV at a small size, whose
// headers are then rewritten to declare `width` × `height`. What they declare is what a reader of
// the header sees (ffprobe agrees); their pixel data stay small, so nothing is decoded at the huge
// size when the limit does its work.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "file_test_support.hpp"

namespace uphill::testing {

namespace oversized_internal {

inline void Put(std::string& bytes, std::size_t at, std::uint32_t value, int n, bool big_endian) {
  for (int k = 0; k < n; ++k) bytes[at + k] = static_cast<char>(value >> (8 * (big_endian ? n - 1 - k : k)));
}

// CRC-32 of PNG chunks (ISO 3309, the polynomial 0xEDB88320, reflected).
inline std::uint32_t Crc32(const std::string& bytes, std::size_t from, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = from; i < from + n; ++i) {
    c ^= static_cast<unsigned char>(bytes[i]);
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

}  // namespace oversized_internal

// A PNG file's bytes whose IHDR declares width × height (its checksum recomputed: a valid header).
inline std::string PngDeclaring(std::uint32_t width, std::uint32_t height) {
  std::vector<unsigned char> encoded;
  cv::imencode(".png", cv::Mat(16, 16, CV_8U, cv::Scalar(128)), encoded);
  std::string bytes(encoded.begin(), encoded.end());
  oversized_internal::Put(bytes, 16, width, 4, true);
  oversized_internal::Put(bytes, 20, height, 4, true);
  oversized_internal::Put(bytes, 29, oversized_internal::Crc32(bytes, 12, 17), 4, true);  // "IHDR" + 13 bytes
  return bytes;
}

// Writes an MJPEG AVI of two 64 × 48 frames whose headers (avih, strh, strf and each frame's SOF0)
// declare width × height.
inline void WriteAviDeclaring(const std::filesystem::path& path, std::uint32_t width, std::uint32_t height) {
  {
    cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25, cv::Size(64, 48));
    for (int i = 0; i < 2; ++i) writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(40, 80, 120 + i)));
  }
  using oversized_internal::Put;
  std::string bytes = ReadBytes(path);
  std::size_t at = bytes.find("avih");
  Put(bytes, at + 8 + 32, width, 4, false);
  Put(bytes, at + 8 + 36, height, 4, false);
  at = bytes.find("strh");
  Put(bytes, at + 8 + 52, width, 2, false);  // rcFrame right, bottom
  Put(bytes, at + 8 + 54, height, 2, false);
  at = bytes.find("strf");
  Put(bytes, at + 8 + 4, width, 4, false);
  Put(bytes, at + 8 + 8, height, 4, false);
  const std::string sof("\xFF\xC0", 2);
  for (at = bytes.find(sof); at != std::string::npos; at = bytes.find(sof, at + 2)) {
    Put(bytes, at + 5, height, 2, true);
    Put(bytes, at + 7, width, 2, true);
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace uphill::testing
