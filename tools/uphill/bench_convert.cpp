// `uphill bench convert` (being written).
#include "commands.hpp"

namespace uphill::cli {

void AddBenchConvert(CLI::App& bench) {
  bench.add_subcommand("convert", "Conversion throughput and accuracy against NumPy");
}

}  // namespace uphill::cli
