#include "io/json_file.hpp"

#include <fstream>

#include "model/input_error.hpp"

namespace uphill {

nlohmann::json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot be opened for reading");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path, std::string("is not valid JSON: ") + e.what());
  }
}

}  // namespace uphill
