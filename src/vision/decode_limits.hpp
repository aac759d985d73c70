// Decode limits: the most pixels an image or a video frame may have for uphill to decode it, read
// from the file's header before anything is decoded; and a budget of decoded bytes that
// concurrent decodes (the frame requests of `uphill serve`) share.
//
// Why: a compressed file says nothing about the memory its decoding takes. A PNG of a few hundred
// kilobytes may declare 20,000 × 20,000 pixels (400 MB per channel once decoded), an MJPEG video
// of one megabyte 8,000 × 8,000 pixels per frame; a calibration decodes every view at once, and
// every frame request of the page decodes a frame. So the size each file declares is checked
// against one limit first: images by their header (PNG IHDR, JPEG SOF, BMP and TIFF headers,
// parsed here because OpenCV has no header-only API), videos by the width and height the
// container declares (cv::VideoCapture reports them on opening, before a frame is decoded).
//
// The limit, kMaxDecodedPixels: 60 million pixels. A 4K video frame (3840 × 2160, 8.3 million)
// and a 50-megapixel photo (8688 × 5792) pass; 8000 × 8000 does not. Such a frame decoded as
// 8-bit BGR takes at most 180 MB. Used by `uphill calibrate camera` and `uphill calibrate scene`
// (their images), `uphill track` (its video), and `uphill serve` (uploads, calibration views,
// frames): docs/serve.md "Limits", docs/calibrate.md.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

namespace uphill {

inline constexpr std::int64_t kMaxDecodedPixels = 60'000'000;

struct PixelSize {
  std::int64_t width = 0, height = 0;
};

// The size a PNG, JPEG, BMP or TIFF file declares in its header (read, never decoded), or nullopt
// when the file is none of these, is cut off before its size, or cannot be opened.
std::optional<PixelSize> ImageHeaderSize(const std::string& path);

// Throws InputError(label) when width × height is more than kMaxDecodedPixels (or either is
// negative), naming both sizes and the limit; `what` says what has that size ("a frame").
void CheckPixelCount(std::int64_t width, std::int64_t height, const std::string& label, const std::string& what);

// Throws InputError(label) unless the file's header declares a size (ImageHeaderSize) within the
// limit: a file that is not a PNG, JPEG, BMP or TIFF image is refused ("cannot be read as an
// image"), since its size cannot be known before decoding it.
void CheckImagePixels(const std::string& path, const std::string& label);

// Thrown when a decode does not fit in its budget in time: the server answers 503 ("try again").
class DecodeBusy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A budget of decoded bytes shared by concurrent decodes. A decode leases its bytes before it
// starts and returns them when the lease ends; a decode that does not fit waits for others to
// end, for at most its `wait`. Thread-safe.
class DecodeBudget {
 public:
  explicit DecodeBudget(std::size_t bytes) : total_(bytes) {}
  DecodeBudget(const DecodeBudget&) = delete;
  DecodeBudget& operator=(const DecodeBudget&) = delete;

  class Lease {
   public:
    Lease() = default;
    Lease(Lease&& other) noexcept : budget_(other.budget_), bytes_(other.bytes_) { other.budget_ = nullptr; }
    Lease& operator=(Lease&&) = delete;
    ~Lease() {
      if (budget_) budget_->Return(bytes_);
    }

   private:
    friend class DecodeBudget;
    Lease(DecodeBudget* budget, std::size_t bytes) : budget_(budget), bytes_(bytes) {}
    DecodeBudget* budget_ = nullptr;
    std::size_t bytes_ = 0;
  };

  // Leases `bytes` for `label` (named in the message). Throws DecodeBusy at once when `bytes`
  // exceed the whole budget, and after `wait` when the others' leases leave too little.
  Lease Acquire(std::size_t bytes, std::chrono::milliseconds wait, const std::string& label);

  std::size_t total() const { return total_; }
  std::size_t in_use() const;
  std::size_t waiting() const;  // decodes waiting for bytes

 private:
  void Return(std::size_t bytes);

  const std::size_t total_;
  mutable std::mutex mutex_;
  std::condition_variable freed_;
  std::size_t in_use_ = 0;
  std::size_t waiting_ = 0;
};

}  // namespace uphill
