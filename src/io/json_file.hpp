// ReadJsonFile: a whole JSON file, for the readers of uphill's JSON formats (experiment.json,
// camera and scene calibration files).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace uphill {

// Throws InputError naming the path when the file cannot be opened or is not valid JSON (the
// parser's message says where).
nlohmann::json ReadJsonFile(const std::string& path);

}  // namespace uphill
