#include "vision/decode_limits.hpp"

#include <array>
#include <cstdlib>
#include <fstream>

#include "model/input_error.hpp"

namespace uphill {
namespace {

// Big- or little-endian unsigned integers of `n` bytes read at the stream's position; nullopt
// when the file ends first.
class HeaderReader {
 public:
  explicit HeaderReader(const std::string& path) : in_(path, std::ios::binary) {}
  bool ok() const { return static_cast<bool>(in_); }
  bool Seek(std::uint64_t offset) { return static_cast<bool>(in_.seekg(static_cast<std::streamoff>(offset))); }
  bool Skip(std::uint64_t n) { return static_cast<bool>(in_.seekg(static_cast<std::streamoff>(n), std::ios::cur)); }
  std::optional<std::uint64_t> Read(int n, bool big_endian) {
    std::array<unsigned char, 8> b{};
    if (!in_.read(reinterpret_cast<char*>(b.data()), n)) return std::nullopt;
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{b[big_endian ? n - 1 - i : i]} << (8 * i);
    return v;
  }

 private:
  std::ifstream in_;
};

std::optional<PixelSize> Both(std::optional<std::uint64_t> w, std::optional<std::uint64_t> h) {
  if (!w || !h) return std::nullopt;
  return PixelSize{static_cast<std::int64_t>(*w), static_cast<std::int64_t>(*h)};
}

// PNG: the signature, then the IHDR chunk: length, "IHDR", width, height (big-endian).
std::optional<PixelSize> PngSize(HeaderReader& in) {
  in.Seek(16);
  const auto w = in.Read(4, true);
  const auto h = in.Read(4, true);
  return Both(w, h);
}

// JPEG: markers after SOI; the first start-of-frame (C0–CF except C4 DHT, C8 JPG, CC DAC) holds
// precision, height, width. A scan (DA) or the end (D9) before it: no size.
std::optional<PixelSize> JpegSize(HeaderReader& in) {
  in.Seek(2);
  for (int markers = 0; markers < 100000; ++markers) {
    auto byte = in.Read(1, true);
    if (!byte) return std::nullopt;
    if (*byte != 0xFF) continue;
    while (byte && *byte == 0xFF) byte = in.Read(1, true);  // fill bytes
    if (!byte) return std::nullopt;
    const std::uint64_t marker = *byte;
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;  // no length
    if (marker == 0xD9 || marker == 0xDA) return std::nullopt;
    const auto length = in.Read(2, true);
    if (!length || *length < 2) return std::nullopt;
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      if (!in.Skip(1)) return std::nullopt;  // precision
      const auto h = in.Read(2, true);
      const auto w = in.Read(2, true);
      return Both(w, h);
    }
    if (!in.Skip(*length - 2)) return std::nullopt;
  }
  return std::nullopt;
}

// BMP: the DIB header's size at 14; the old 12-byte header has 16-bit sizes, the others signed
// 32-bit ones (a negative height: rows top to bottom).
std::optional<PixelSize> BmpSize(HeaderReader& in) {
  in.Seek(14);
  const auto header = in.Read(4, false);
  if (!header) return std::nullopt;
  if (*header == 12) {
    const auto w = in.Read(2, false);
    const auto h = in.Read(2, false);
    return Both(w, h);
  }
  const auto w = in.Read(4, false);
  const auto h = in.Read(4, false);
  if (!w || !h) return std::nullopt;
  return PixelSize{std::llabs(static_cast<std::int32_t>(*w)), std::llabs(static_cast<std::int32_t>(*h))};
}

// TIFF: the byte order, 42, the first directory's offset; in it, tags 256 (width) and 257
// (height), SHORT or LONG. The first directory is the image OpenCV decodes.
std::optional<PixelSize> TiffSize(HeaderReader& in, bool big_endian) {
  in.Seek(4);
  const auto directory = in.Read(4, big_endian);
  if (!directory || !in.Seek(*directory)) return std::nullopt;
  const auto count = in.Read(2, big_endian);
  if (!count) return std::nullopt;
  std::optional<std::uint64_t> w, h;
  for (std::uint64_t i = 0; i < *count && !(w && h); ++i) {
    const auto tag = in.Read(2, big_endian);
    const auto type = in.Read(2, big_endian);
    if (!tag || !type || !in.Skip(4)) return std::nullopt;
    const bool is_short = *type == 3;
    const auto value = in.Read(is_short ? 2 : 4, big_endian);
    if (!value || (is_short && !in.Skip(2))) return std::nullopt;
    if (*type != 3 && *type != 4) continue;
    if (*tag == 256) w = value;
    if (*tag == 257) h = value;
  }
  return Both(w, h);
}

}  // namespace

std::optional<PixelSize> ImageHeaderSize(const std::string& path) {
  HeaderReader in(path);
  if (!in.ok()) return std::nullopt;
  const auto magic = in.Read(4, true);
  if (!magic) return std::nullopt;
  if (*magic == 0x89504E47) return PngSize(in);
  if ((*magic >> 16) == 0xFFD8) return JpegSize(in);
  if ((*magic >> 16) == 0x424D) return BmpSize(in);  // "BM"
  if (*magic == 0x49492A00) return TiffSize(in, false);  // "II*\0"
  if (*magic == 0x4D4D002A) return TiffSize(in, true);   // "MM\0*"
  return std::nullopt;
}

void CheckPixelCount(std::int64_t width, std::int64_t height, const std::string& label, const std::string& what) {
  const bool over = width < 0 || height < 0 || (width > 0 && height > kMaxDecodedPixels / width);
  if (!over) return;
  const std::string size = std::to_string(width) + " × " + std::to_string(height) + " pixels";
  throw InputError(label, what + " of " + size + " is more than uphill decodes: at most " +
                              std::to_string(kMaxDecodedPixels / 1'000'000) +
                              " million pixels (a 4K video frame or a 50-megapixel photo)");
}

void CheckImagePixels(const std::string& path, const std::string& label) {
  const std::optional<PixelSize> size = ImageHeaderSize(path);
  if (!size)
    throw InputError(label, "cannot be read as an image: not a PNG, JPEG, BMP or TIFF file whose header gives its "
                            "size (the formats uphill checks before decoding)");
  CheckPixelCount(size->width, size->height, label, "an image");
}

DecodeBudget::Lease DecodeBudget::Acquire(std::size_t bytes, std::chrono::milliseconds wait, const std::string& label) {
  const auto mib = [](std::size_t b) {  // rounded up, in KiB below 1 MiB
    return b < (1u << 20) ? std::to_string((b + 1023) >> 10) + " KiB" : std::to_string((b + (1u << 20) - 1) >> 20) + " MiB";
  };
  if (bytes > total_)
    throw DecodeBusy(label + ": decoding it takes " + mib(bytes) + ", more than the server's budget for decoding (" +
                     mib(total_) + ")");
  std::unique_lock lock(mutex_);
  ++waiting_;
  const bool fits = freed_.wait_for(lock, wait, [&] { return in_use_ + bytes <= total_; });
  --waiting_;
  if (!fits)
    throw DecodeBusy(label + ": the server is busy decoding other frames (" + mib(in_use_) + " of its " + mib(total_) +
                     " budget in use): try again");
  in_use_ += bytes;
  return Lease(this, bytes);
}

std::size_t DecodeBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return in_use_;
}

std::size_t DecodeBudget::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_;
}

void DecodeBudget::Return(std::size_t bytes) {
  {
    std::lock_guard lock(mutex_);
    in_use_ -= bytes;
  }
  freed_.notify_all();
}

}  // namespace uphill
