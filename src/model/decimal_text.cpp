#include "model/decimal_text.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace uphill {
namespace {

// 10^0 … 10^22: every one exact in binary64.
constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                               1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr std::uint64_t kPow10Int[10] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000,
                                         1000000000};
// The integer path writes whole blocks of kCopy characters (only the first few count) from a
// buffer whose digits end at kDigitsEnd, and needs kFastRoom characters of room.
constexpr std::size_t kCopy = 16, kDigitsEnd = 24, kDigitsBuffer = kDigitsEnd + kCopy;
constexpr std::ptrdiff_t kFastRoom = 48;
// Below this, y < 2^50: y − floor(y) is exact and the margin y·2^−52 stays under 1/4.
constexpr double kLargestScaled = 1e15;

// round(a·10^k) when it is certainly the rounding of the exact product (see the header), else -1.
// a ≥ 0 finite, |k| ≤ 22.
inline std::int64_t RoundedScaled(double a, int k) {
  const double y = k >= 0 ? a * kPow10[k] : a / kPow10[-k];
  if (!(y < kLargestScaled)) return -1;
  const std::int64_t whole = static_cast<std::int64_t>(y);  // floor: y ≥ 0
  const double frac = y - static_cast<double>(whole);         // exact
  if (std::abs(frac - 0.5) <= y * 0x1p-52) return -1;
  return whole + (frac > 0.5 ? 1 : 0);
}

// The decimal digits of n, at least `width` of them (zero-padded on the left), written so that
// they end at `end`; returns their beginning.
inline char* DigitsBefore(char* end, std::uint64_t n, int width) {
  static constexpr char kPairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  char* p = end;
  while (n >= 100) {
    const std::uint64_t pair = n % 100;
    n /= 100;
    p -= 2;
    std::memcpy(p, kPairs + 2 * pair, 2);
  }
  if (n >= 10) {
    p -= 2;
    std::memcpy(p, kPairs + 2 * n, 2);
  } else {
    *--p = static_cast<char>('0' + n);
  }
  while (end - p < width) *--p = '0';
  return p;
}

}  // namespace

char* FixedText(char* first, char* last, double v, int precision) {
  const double a = std::abs(v);
  // At most 16 integer digits, a point and 9 decimals, and the sign, on the integer path.
  if (precision >= 0 && precision <= 9 && last - first >= kFastRoom && a < kLargestScaled) {
    const std::int64_t n = RoundedScaled(a, precision);
    if (n >= 0) {
      // The digits (at least one before the point), then the point moved in.
      char digits[kDigitsBuffer];
      char* const end = digits + kDigitsEnd;
      const char* d = DigitsBefore(end, static_cast<std::uint64_t>(n), precision + 1);
      char* p = first;
      *p = '-';
      p += std::signbit(v);
      const std::size_t whole = static_cast<std::size_t>(end - d - precision);
      std::memcpy(p, d, kCopy);  // whole ≤ 16 of them count
      p += whole;
      if (precision > 0) {
        *p++ = '.';
        std::memcpy(p, end - precision, kCopy);  // precision of them count
        p += precision;
      }
      return p;
    }
  }
  return std::to_chars(first, last, v, std::chars_format::fixed, precision).ptr;
}

char* GeneralText(char* first, char* last, double v, int precision) {
  const double a = std::abs(v);
  if (precision >= 1 && precision <= 9 && last - first >= kFastRoom && std::isnormal(a)) {
    // a in [2^(e2−1), 2^e2): its decimal exponent is e10 or e10 + 1, e10 = floor((e2 − 1)·log10 2)
    // (78913 / 2^18 is log10 2 to 6 digits: exact floors for |e2| < 1650).
    const int e2 = static_cast<int>(std::bit_cast<std::uint64_t>(a) >> 52) - 1022;  // a normal
    int exponent = ((e2 - 1) * 78913) >> 18;
    const auto digits_at = [a, precision](int e) {
      const int k = precision - 1 - e;
      return k >= -22 && k <= 22 ? RoundedScaled(a, k) : -1;
    };
    std::int64_t n = digits_at(exponent);
    if (n >= 0 && n < static_cast<std::int64_t>(kPow10Int[precision - 1])) n = digits_at(--exponent);
    if (n >= static_cast<std::int64_t>(kPow10Int[precision])) n = digits_at(++exponent);  // rounds up to one more digit
    if (n >= 0) {
      // n has exactly `precision` digits; printf drops the trailing zeros.
      char buffer[kDigitsBuffer];
      const char* digits = DigitsBefore(buffer + kDigitsEnd, static_cast<std::uint64_t>(n), precision);
      int count = precision;
      while (count > 1 && digits[count - 1] == '0') --count;
      char* p = first;
      *p = '-';
      p += std::signbit(v);
      // Copies of kCopy characters of which the first `count`, `whole`, ... count.
      if (exponent >= -4 && exponent < precision) {  // %f with precision − 1 − exponent decimals
        if (exponent >= 0) {
          const int whole = exponent + 1;
          std::memcpy(p, digits, kCopy);
          p += whole;
          if (count > whole) {
            *p++ = '.';
            std::memcpy(p, digits + whole, kCopy);
            p += count - whole;
          }
        } else {
          std::memcpy(p, "0.00000", 8);  // "0." and −exponent − 1 ≤ 3 zeros
          p += 1 - exponent;
          std::memcpy(p, digits, kCopy);
          p += count;
        }
      } else {  // %e with precision − 1 decimals: d[.ddd]e±XX
        *p++ = digits[0];
        if (count > 1) {
          *p++ = '.';
          std::memcpy(p, digits + 1, kCopy);
          p += count - 1;
        }
        *p++ = 'e';
        *p++ = exponent < 0 ? '-' : '+';
        const int x = exponent < 0 ? -exponent : exponent;
        if (x < 10) *p++ = '0';
        p = std::to_chars(p, last, x).ptr;
      }
      return p;
    }
  }
  return std::to_chars(first, last, v, std::chars_format::general, precision).ptr;
}

}  // namespace uphill
