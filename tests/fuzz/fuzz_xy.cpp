// Fuzz target: ReadXy (the `uphill fit --xy` reader, io/xy_table.hpp) and the four line fits
// that `uphill fit --xy --method ols|wls|york|robust` runs on what it read. Only uphill::InputError
// may escape; anything else (a crash, a sanitizer report, another exception) is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "fit/least_squares_line.hpp"
#include "fit/robust_line.hpp"
#include "fit/york_line.hpp"
#include "io/xy_table.hpp"
#include "model/input_error.hpp"

namespace {

using namespace uphill;

template <typename FitFunction>
void TryFit(FitFunction fit) {
  try {
    (void)fit();
  } catch (const InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  XyTable table;
  try {
    table = ReadXy(in, "fuzz.csv");
  } catch (const InputError&) {
    return 0;
  }
  // Contract: every read value is finite, and the columns line up.
  for (const auto* column : {&table.x, &table.y, &table.u_x, &table.u_y})
    for (double v : *column)
      if (!std::isfinite(v)) {
        std::fprintf(stderr, "fuzz_xy: a non-finite value was read\n");
        std::abort();
      }
  if (table.y.size() != table.x.size() || (!table.u_x.empty() && table.u_x.size() != table.x.size()) ||
      (!table.u_y.empty() && table.u_y.size() != table.x.size())) {
    std::fprintf(stderr, "fuzz_xy: columns of different lengths\n");
    std::abort();
  }
  if (table.x.size() > 64) return 0;  // the fits are Ceres's; keep the runs short
  LineData line;
  line.x = table.x;
  line.y = table.y;
  line.u_x = table.u_x;
  line.u_y = table.u_y;
  TryFit([&] { return FitOrdinaryLeastSquares(line); });
  TryFit([&] { return FitWeightedLeastSquares(line); });
  TryFit([&] { return FitErrorsInVariables(line); });
  TryFit([&] { return FitRobust(line); });
  return 0;
}
