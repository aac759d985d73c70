// `uphill bench <what>`: benchmarks that print work-precision tables (never timed unit tests).
#include "commands.hpp"

namespace uphill::cli {

void AddBenchCommand(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: speed against error, with peers");
  bench->require_subcommand(1);
  AddBenchConvert(*bench);
  AddBenchFit(*bench);
  AddBenchMotion(*bench);
  AddBenchTrack(*bench);
}

}  // namespace uphill::cli
