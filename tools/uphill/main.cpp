// uphill: analysis toolkit for the "rolling uphill" rail apparatus. See README.md.
#include <iostream>

#include "commands.hpp"
#include "model/input_error.hpp"
#include "self_documentation.hpp"
#include "vision_program.hpp"

namespace uphill::cli {
int& ExitStatus() {
  static int status = 0;
  return status;
}
}  // namespace uphill::cli

// The same main for `uphill` and `uphill-vision` (vision_program.hpp).
int main(int argc, char** argv) {
  uphill::cli::RememberArguments(argc, argv);
  CLI::App app{"uphill: analysis toolkit for the rolling-uphill rail apparatus", "uphill"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "uphill " UPHILL_VERSION);
  uphill::cli::AddConvertCommand(app);
  uphill::cli::AddFitCommand(app);
  uphill::cli::AddServeCommand(app);
  uphill::cli::AddSimulateCommand(app);
  uphill::cli::AddPaperFiguresCommand(app);
  uphill::cli::AddCalibrateCommand(app);
  uphill::cli::AddTrackCommand(app);
  uphill::cli::AddAnalyseTrackCommand(app);
  uphill::cli::AddBenchCommand(app, std::vector<std::string>(argv + 1, argv + argc));
  uphill::cli::AddSelfDocumentationFlags(app, "uphill " UPHILL_VERSION);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const uphill::InputError& e) {
    std::cerr << "uphill: " << e.what() << "\n";
    return 2;
  } catch (const std::runtime_error& e) {
    // Environment problems (a file that cannot be written, gnuplot missing): not a bug.
    std::cerr << "uphill: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "uphill: internal error: " << e.what() << "\n";
    return 1;
  }
  return uphill::cli::ExitStatus();
}
