// The subcommands of the `uphill` program. Each lives in its own file and adds itself to the
// application here; main.cpp only wires them together and maps errors to exit codes.
//
// Exit codes (documented in docs/exit-codes.md): 0 success; 1 internal error; 2 bad input (a flag, a
// file, a row or a column), with a one-line message naming it and the rule broken.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace uphill::cli {

// Exit status of a subcommand run, set by the subcommand's callback.
int& ExitStatus();

void AddConvertCommand(CLI::App& app);
// `bench`: the benchmarks of src/bench (bench_command.cpp); `arguments` (argv without the
// program name) go into the benchmarks' record.
void AddBenchCommand(CLI::App& app, const std::vector<std::string>& arguments);
// `fit` and `report` (fit_command.cpp).
void AddFitCommand(CLI::App& app);
// `serve`: the measurement-entry web page (serve_command.cpp, src/server/).
void AddServeCommand(CLI::App& app);
// `simulate`: the rolling motion released at --x0 (simulate_command.cpp, src/motion/).
void AddSimulateCommand(CLI::App& app);
// `paper-figures`: the seed paper's model figures (paper_figures_command.cpp).
void AddPaperFiguresCommand(CLI::App& app);
// `calibrate camera|scene|target`: camera calibration (calibrate_command.cpp, src/vision/).
void AddCalibrateCommand(CLI::App& app);
// `track`: the ball's centre in every frame of a calibrated video (track_command.cpp, src/vision/).
void AddTrackCommand(CLI::App& app);
// `analyse-track`: events and model fit of a ball track (analyse_track_command.cpp, src/vision/).
void AddAnalyseTrackCommand(CLI::App& app);

}  // namespace uphill::cli
