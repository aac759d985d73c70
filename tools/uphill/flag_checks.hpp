// Flags the user gave that the command would not use, or gave empty, are refused (exit 2, naming
// the flag): a flag that is silently ignored leaves the user believing it took effect.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace uphill::cli {

// Whether `flag` (e.g. "--at-x") was on the command line, even with an empty value.
bool Given(const CLI::App* command, const std::string& flag);

// Throws InputError(flag, "is empty …") when `flag` was given with an empty or blank value.
void RefuseEmpty(const CLI::App* command, const std::string& flag, const std::string& value,
                 const std::string& example);

// Throws InputError(flag, why) when `flag` was given but `ignored` says it would have no effect.
void RefuseIgnored(const CLI::App* command, const std::string& flag, bool ignored, const std::string& why);

}  // namespace uphill::cli
