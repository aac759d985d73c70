// uphill: analysis toolkit for the "rolling uphill" rail apparatus. See README.md.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "model/environment_error.hpp"
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
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line, like every other refusal (CLI11's own adds "Run with --help …").
    std::string message = e.what();
    if (argc > 1 && argv[1][0] != '-' && dynamic_cast<const CLI::RequiredError*>(&e) != nullptr &&
        app.get_subcommands().empty()) {
      std::string names;
      for (const CLI::App* sub : app.get_subcommands({}))
        if (!sub->get_name().empty()) names += (names.empty() ? "" : ", ") + sub->get_name();
      message = std::string(argv[1]) + ": no such command (the commands: " + names + ")";
    }
    std::cerr << "uphill: " << message << " (uphill --help lists the flags)\n";
    return 2;
  } catch (const uphill::InputError& e) {
    std::cerr << "uphill: " << e.what() << "\n";
    return 2;
  } catch (const uphill::EnvironmentError& e) {
    // The computer refused (a file that cannot be written, gnuplot missing, a port in use): the
    // user's to fix, not a bug.
    std::cerr << "uphill: " << e.what() << "\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "uphill: " << (e.path1().empty() ? std::string() : e.path1().string() + ": ") << e.code().message()
              << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "uphill: internal error: " << e.what() << "\n";
    return 1;
  }
  return uphill::cli::ExitStatus();
}
