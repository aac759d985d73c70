#include "linear_light.hpp"

#include <cmath>

namespace uphill::internal {

std::array<float, 256> LinearTable(Transfer transfer) {
  std::array<float, 256> table;
  for (int k = 0; k < 256; ++k) {
    const double e = k / 255.0;
    // sRGB (IEC 61966-2-1); phones' Rec. 709 video differs from it by less than the 8-bit step
    // over most of the range.
    const double linear = transfer == Transfer::kLinear ? e : e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    table[k] = static_cast<float>(linear);
  }
  return table;
}

}  // namespace uphill::internal
