// A fitted value with its standard uncertainty as a paper quotes it: the uncertainty rounded to
// two significant digits and the value to the same decimal place (JCGM 100:2008, the GUM, 7.2.6:
// "it is usually sufficient to quote u at most to two significant digits"). Used by the report's
// summary (report_summary.hpp) and its LaTeX tables (latex_report.hpp), so the number a reader
// copies from either is the same text.
//
//   QuoteValue(0.050312, 0.0012345)   value "0.0503", uncertainty "0.0012", concise "0.0503(12)"
//   QuoteValue(-12.3456, 0.87)        "-12.35", "0.87", "-12.35(87)"
//   QuoteValue(123.4, 15.6)           "123", "16", "123(16)"
//   QuoteValue(1.2345, 0) or a NaN u  "1.2345" (6 significant digits), "", "1.2345": no uncertainty
// `decimals` is the number of digits after the point of both texts (0 for integers). The value
// must be finite (the analysis lets no NaN through); a NaN or infinite value prints "-".
#pragma once

#include <string>

namespace uphill {

struct QuotedValue {
  std::string value;        // the value rounded to the uncertainty's last digit
  std::string uncertainty;  // two significant digits; "" when there is none
  std::string concise;      // value(uncertainty in units of the last digit), siunitx's \num syntax
  int decimals = 0;

  std::string PlusMinus() const { return uncertainty.empty() ? value : value + " ± " + uncertainty; }
};

QuotedValue QuoteValue(double value, double uncertainty);

}  // namespace uphill
