// Numbers as text, in the two ways uphill writes them.
//
//   ExactText(v)        17 significant digits: the double exactly as stored, for error messages
//                       ("D: must be > 0 (got -0.0030000000000000001)"), so that what the user
//                       sees is what the program saw.
//   Printf(format, v)   one number through a printf format ("%.3f"), for tables and sentences.
#pragma once

#include <cstdio>
#include <string>

namespace uphill {

inline std::string ExactText(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

inline std::string Printf(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

}  // namespace uphill
