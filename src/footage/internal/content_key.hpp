// A short name for a piece of content (cache keys of the footage: a condition's description, a
// POV-Ray scene text): 16 hex digits of its 64-bit FNV-1a hash. Not cryptographic; the caches
// it keys hold renders of descriptions made by uphill itself.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace uphill::internal {

inline std::string ContentKey(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(h));
  return buffer;
}

}  // namespace uphill::internal
