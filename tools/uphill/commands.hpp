// The subcommands of the `uphill` program. Each lives in its own file and adds itself to the
// application here; main.cpp only wires them together and maps errors to exit codes.
//
// Exit codes (documented in README.md): 0 success; 1 internal error; 2 bad input (a flag, a
// file, a row or a column), with a one-line message naming it and the rule broken.
#pragma once

#include <CLI/CLI.hpp>

namespace uphill::cli {

// Exit status of a subcommand run, set by the subcommand's callback.
int& ExitStatus();

void AddConvertCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);
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

// `uphill bench <what>`: each benchmark adds itself to the bench subcommand.
void AddBenchConvert(CLI::App& bench);
void AddBenchFit(CLI::App& bench);  // bench_fit.cpp
void AddBenchMotion(CLI::App& bench);  // bench_motion.cpp
void AddBenchTrack(CLI::App& bench);  // bench_track.cpp

}  // namespace uphill::cli
