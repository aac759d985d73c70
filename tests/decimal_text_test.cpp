// FixedText and GeneralText (model/decimal_text.hpp) against two independent truths: libstdc++'s
// std::to_chars with a precision (Ryu printf) and glibc's snprintf ("%.*f", "%.*g"), which must
// give the same characters for every value (C++17 [charconv.to.chars], C 7.21.6.1).
#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "model/decimal_text.hpp"

namespace {

using uphill::FixedText;
using uphill::GeneralText;
using uphill::kDecimalTextRoom;

std::string Ours(double v, int precision, bool general) {
  char buffer[kDecimalTextRoom];
  char* end = general ? GeneralText(buffer, buffer + sizeof buffer, v, precision)
                      : FixedText(buffer, buffer + sizeof buffer, v, precision);
  return std::string(buffer, end);
}

std::string ToChars(double v, int precision, bool general) {
  char buffer[kDecimalTextRoom];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v,
                               general ? std::chars_format::general : std::chars_format::fixed, precision);
  return std::string(buffer, r.ptr);
}

std::string Snprintf(double v, int precision, bool general) {
  char buffer[kDecimalTextRoom + 8];
  std::snprintf(buffer, sizeof buffer, general ? "%.*g" : "%.*f", precision, v);
  return buffer;
}

// Counts mismatches (and reports the first few) of both functions at precisions 0/1 … 9, or only
// at 6 (what `convert --csv` prints).
int CheckAll(const std::vector<double>& values, bool with_snprintf = true, bool only_6 = false) {
  int failures = 0;
  for (const double v : values)
    for (int general = 0; general < 2; ++general)
      for (int p = only_6 ? 6 : general; p <= (only_6 ? 6 : 9); ++p) {
        const std::string ours = Ours(v, p, general), truth = ToChars(v, p, general);
        const bool ok = ours == truth && (!with_snprintf || truth == Snprintf(v, p, general));
        if (!ok && ++failures <= 5)
          ADD_FAILURE() << (general ? "%." : "%.") << p << (general ? "g" : "f") << " of "
                        << std::bit_cast<std::uint64_t>(v) << " (" << truth << "): got " << ours
                        << ", snprintf " << Snprintf(v, p, general);
      }
  return failures;
}

// Both signs, and the neighbours up to 3 ulp away.
void AddWithNeighbours(std::vector<double>* out, double v) {
  for (double s : {v, -v}) {
    double up = s, down = s;
    out->push_back(s);
    for (int i = 0; i < 3; ++i) {
      up = std::nextafter(up, std::numeric_limits<double>::infinity());
      down = std::nextafter(down, -std::numeric_limits<double>::infinity());
      out->push_back(up);
      out->push_back(down);
    }
  }
}

TEST(DecimalText, RandomValuesOfEveryMagnitudeAreToCharsAndPrintf) {
  // 10^6 values: uniform over the bit patterns of finite doubles (every exponent), over the
  // magnitudes the converter prints (angles in degrees, lengths in mm), and small integers.
  std::mt19937_64 rng(20261123);
  std::vector<double> values;
  values.reserve(1'000'000);
  while (values.size() < 250'000) {
    const double v = std::bit_cast<double>(rng());
    if (std::isfinite(v)) values.push_back(v);
  }
  std::uniform_real_distribution<double> degrees(-360.0, 360.0), log_length(-8.0, 8.0);
  for (int i = 0; i < 250'000; ++i) values.push_back(degrees(rng));
  for (int i = 0; i < 250'000; ++i) values.push_back(std::pow(10.0, log_length(rng)) * (i % 2 ? 1 : -1));
  for (int i = 0; i < 250'000; ++i) values.push_back(static_cast<double>(static_cast<std::int64_t>(rng() % 2'000'001) - 1'000'000));
  // Every value at precision 6 against to_chars; every 10th at all precisions, also against snprintf.
  EXPECT_EQ(CheckAll(values, /*with_snprintf=*/false, /*only_6=*/true), 0);
  std::vector<double> some;
  for (std::size_t i = 0; i < values.size(); i += 10) some.push_back(values[i]);
  EXPECT_EQ(CheckAll(some), 0);
}

TEST(DecimalText, ExactTiesAndTheirNeighboursRoundAsPrintf) {
  // Exact ties: j/2^m has a 5 in the last place of its decimal expansion, so at the right
  // precision it lies exactly halfway (0.0078125 = 1/128 at %.6f, 2.5 at %.0f, 0.125 at %.2f):
  // printf rounds these to even. Their neighbours one ulp away are not ties.
  std::vector<double> values;
  for (int m = 0; m <= 30; ++m)
    for (int j = 1; j <= 2001; j += 2) AddWithNeighbours(&values, std::ldexp(j, -m));
  // Decimal ties (k + 1/2)·10^-p and (k + 1/2)·10^(e) at every precision, as the nearest double
  // (not exact, but within an ulp of the tie: the margin's hard case).
  for (int p = 0; p <= 9; ++p)
    for (int k = 0; k < 3000; k += 7) AddWithNeighbours(&values, (k + 0.5) / std::pow(10.0, p));
  for (int e = -30; e <= 30; ++e)
    for (int k = 100; k < 1000; k += 37) AddWithNeighbours(&values, (k + 0.5) * std::pow(10.0, e));
  // The switch of %g to the exponent form and the digit-count boundaries: 999999.5, 9.9999995, ...
  for (int e = -30; e <= 30; ++e)
    for (int digits = 1; digits <= 9; ++digits) {
      const double nines = 1.0 - 0.5 * std::pow(10.0, -digits);
      AddWithNeighbours(&values, nines * std::pow(10.0, e));
      AddWithNeighbours(&values, std::pow(10.0, e));
    }
  EXPECT_EQ(CheckAll(values), 0);
}

TEST(DecimalText, ZerosHugeTinyAndNonFiniteValuesAreToCharsAndPrintf) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> values = {0.0, -0.0, 1e-7, -1e-7, -4e-7, -5e-7, -6e-7, 0.5, -0.5, 1.5, 2.5,
                                std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min(),
                                std::numeric_limits<double>::max(), 1e15, 1e15 - 0.5, 1e16, 9.007199254740993e15,
                                1e22, 1e23, 1e-22, 1e-23, 1e300, 1e-300, inf, -inf};
  std::vector<double> all;
  for (double v : values) AddWithNeighbours(&all, v);
  all.push_back(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(CheckAll(all), 0);
  // The sign of zero and of negative values that round to zero, written out (the truth is
  // C 7.21.6.1: the sign is printed for a negative value, also when its digits are all zero).
  EXPECT_EQ(Ours(-0.0, 6, false), "-0.000000");
  EXPECT_EQ(Ours(-1e-9, 6, false), "-0.000000");
  EXPECT_EQ(Ours(-0.0, 6, true), "-0");
  EXPECT_EQ(Ours(0.0078125, 6, false), "0.007812");  // a tie, to even
  EXPECT_EQ(Ours(999999.5, 6, true), "1e+06");
  EXPECT_EQ(Ours(123.456, 6, true), "123.456");
  EXPECT_EQ(Ours(0.000123456789, 6, true), "0.000123457");
  EXPECT_EQ(Ours(-1.5e-5, 6, true), "-1.5e-05");
}

TEST(DecimalText, ASmallBufferGetsToCharsAnswer) {
  // Too little room: the result is what to_chars does (returns `last`, errc::value_too_large).
  char small[4];
  EXPECT_EQ(FixedText(small, small + sizeof small, 123.25, 6), small + sizeof small);
  char fits[32];
  char* end = FixedText(fits, fits + 10, 3.25, 2);  // room for "3.25" through to_chars
  EXPECT_EQ(std::string(fits, end), "3.25");
}

}  // namespace
