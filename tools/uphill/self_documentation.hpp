// The program's manual pages and its bash completion, generated from its own CLI11 command tree,
// so that they list exactly the subcommands, flags and arguments the program parses and cannot
// drift from it. The build runs the hidden flags below (tools/uphill/CMakeLists.txt) and
// `cmake --install` installs the results (share/man/man1, share/bash-completion/completions).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace uphill::cli {

// Writes uphill.1 and one page per subcommand at every level (uphill-convert.1,
// uphill-calibrate-camera.1, ...) into `dir` (created if needed): roff with the man(7) macros,
// NAME, SYNOPSIS, DESCRIPTION (the command's description and footer), ARGUMENTS, OPTIONS,
// COMMANDS, and on uphill(1) the units, exit status and installed files. Hidden options and
// subcommands are left out. Returns the number of pages written.
int WriteManPages(const CLI::App& root, const std::string& dir, const std::string& version);

// A bash completion script for the program named root.get_name(): subcommands, the flags of the
// command being typed, the choices of flags with a CLI::IsMember check, files for other values.
// Needs only bash (not the bash-completion package's helpers).
std::string BashCompletion(const CLI::App& root);

// Adds the hidden flags `--man-pages DIR` and `--bash-completion FILE` (FILE "-" = stdout), which
// write the above from `app`'s tree once every subcommand is added, and end the run with exit 0.
void AddSelfDocumentationFlags(CLI::App& app, const std::string& version);

}  // namespace uphill::cli
