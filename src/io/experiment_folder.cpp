#include "io/experiment_folder.hpp"

#include <filesystem>

#include "io/json_file.hpp"
#include "model/input_error.hpp"

namespace uphill {

const std::set<std::string>& ExperimentKeys() {
  static const std::set<std::string> keys = {"format", "title", "operator", "date", "notes", "body",
                                             "apparatus", "uncertainties"};
  return keys;
}

const std::set<std::string>& BodyKeys() {
  static const std::set<std::string> keys = {"type", "R", "a", "b", "h"};
  return keys;
}

const std::set<std::string>& ApparatusKeys() {
  static const std::set<std::string> keys = {"L", "H", "D", "theta", "alpha", "rod_diameter", "L_convention"};
  return keys;
}

const std::set<std::string>& UncertaintyKeys() {
  static const std::set<std::string> keys = {"L", "H", "D", "Y", "R", "a", "b", "h", "theta", "alpha", "rod_diameter"};
  return keys;
}

const std::vector<std::string>& MeasurementLabelColumns() {
  static const std::vector<std::string> columns = {"trial", "series", "note"};
  return columns;
}

const std::vector<std::string>& MeasurementQuantities() {
  static const std::vector<std::string> columns = {"L", "H", "D", "Y", "u_L", "u_H", "u_D", "u_Y"};
  return columns;
}

ExperimentFolder ReadExperimentJson(const std::string& directory) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(directory)) throw InputError(directory, "is not an experiment folder");
  ExperimentFolder folder;
  folder.directory = directory;
  folder.json_path = (fs::path(directory) / kExperimentJsonFile).string();
  folder.csv_path = (fs::path(directory) / kMeasurementsCsvFile).string();
  folder.metadata = ReadJsonFile(folder.json_path);
  return folder;
}

std::optional<CsvTable> ReadMeasurements(const ExperimentFolder& folder) {
  if (!std::filesystem::exists(folder.csv_path)) return std::nullopt;
  return ReadCsvFile(folder.csv_path);
}

}  // namespace uphill
