#include "flag_checks.hpp"

#include "model/input_error.hpp"

namespace uphill::cli {

bool Given(const CLI::App* command, const std::string& flag) { return command && command->count(flag) > 0; }

void RefuseEmpty(const CLI::App* command, const std::string& flag, const std::string& value,
                 const std::string& example) {
  if (Given(command, flag) && value.find_first_not_of(" \t") == std::string::npos)
    throw InputError(flag, "is empty (give " + example + ")");
}

void RefuseIgnored(const CLI::App* command, const std::string& flag, bool ignored, const std::string& why) {
  if (ignored && Given(command, flag)) throw InputError(flag, why);
}

}  // namespace uphill::cli
