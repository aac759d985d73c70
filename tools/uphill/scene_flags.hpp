// The flags that describe one apparatus setting, shared by every subcommand that needs a scene
// (convert, simulate, track): --body, --R/--a/--b/--h, --L/--H/--D or --theta/--alpha,
// --rod-diameter, --L-along-rail, --label and the uncertainties --u-<name>.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>

#include "io/configuration.hpp"

namespace uphill::cli {

struct SceneFlags {
  std::map<std::string, std::string> values;  // field name (ConfigurationFieldNames) -> text
  bool along_rail = false;
};

// Adds the flags to `command`; values land in `flags` after parsing.
void AddSceneFlags(CLI::App* command, SceneFlags* flags);

// "--rod-diameter" for "rod_diameter", "--u-L" for "u_L".
std::string FlagName(const std::string& field);

// The flags as a field source (each field named by its flag in messages).
FieldSource FlagSource(const SceneFlags& flags);

}  // namespace uphill::cli
