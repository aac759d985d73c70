// FixedText, GeneralText: printf's "%.<p>f" and "%.<p>g" of a double, byte for byte, for output
// that prints millions of numbers (`uphill convert --batch --csv`).
//
//   FixedText(first, last, v, p)     = std::to_chars(first, last, v, std::chars_format::fixed, p)
//   GeneralText(first, last, v, p)   = std::to_chars(first, last, v, std::chars_format::general, p)
// (the same characters as printf's %.<p>f / %.<p>g in the "C" locale: the value correctly rounded
// to p decimals / p significant digits, ties to even, %g without trailing zeros). Both return the
// end of the text, or `last` when it does not fit (as to_chars' ptr with errc::value_too_large).
//
// How, and why it is exact. The digits are the integer N = round(|v|·10^k) (k = p for %f, k =
// p − 1 − exponent for %g) printed as an integer with the decimal point put in. y = |v|·10^k (or
// |v| / 10^−k) is one correctly rounded IEEE operation on the exact power of ten 10^|k| (|k| ≤ 22),
// so |y − |v|·10^k| ≤ y·2^−53. Rounding to an integer changes only at half-integers: when y is
// farther than y·2^−52 from floor(y) + 1/2, the exact product rounds to the integer that y rounds
// to. Otherwise (the exact product may sit on or beside a tie), and for values whose digits need
// more than 10^15 or a power beyond 10^22 (huge and tiny magnitudes, 0 for %g, NaN, ±inf), the
// text is std::to_chars's own. Most values take the integer path, which is several times faster.
//
// Precision: p in 0 … 9 (FixedText) and 1 … 9 (GeneralText); any other p goes to std::to_chars.
// Room: a buffer of kDecimalTextRoom characters always fits (%f of the largest double).
//
// Hard cases (tests/decimal_text_test.cpp compares with std::to_chars and snprintf): exact ties
// (v = j/2^m, e.g. 0.0078125 at p = 6), values one ulp beside a tie, negative zero ("-0.000000",
// "-0"), negative values that round to zero ("-0.000000"), %g at the switch to the exponent
// form (999999.5 → "1e+06"), subnormals, DBL_MAX, NaN and infinities.
#pragma once

#include <cstddef>

namespace uphill {

// %f of the largest double: 309 integer digits, sign, point and 9 decimals.
inline constexpr std::size_t kDecimalTextRoom = 330;

char* FixedText(char* first, char* last, double v, int precision);
char* GeneralText(char* first, char* last, double v, int precision);

}  // namespace uphill
