#include "io/experiment_folder.hpp"

#include <filesystem>
#include <sstream>

#include "io/json_file.hpp"
#include "model/input_error.hpp"

namespace uphill {

const std::set<std::string>& ExperimentKeys() {
  static const std::set<std::string> keys = {"format", "title", "operator", "date", "notes", "body",
                                             "apparatus", "uncertainties", "camera", "scenes",
                                             "video_analysis"};
  return keys;
}

const std::set<std::string>& ExperimentKeysOfVersion2() {
  static const std::set<std::string> keys = {"camera", "scenes", "video_analysis"};
  return keys;
}

const std::set<std::string>& VideoAnalysisKeys() {
  static const std::set<std::string> keys = {"fit", "u_x", "g"};
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

const std::string& MeasurementExclusionColumn() {
  static const std::string column = "excluded";
  return column;
}

const std::vector<std::string>& MeasurementVideoColumns() {
  static const std::vector<std::string> columns = {"video", "scene"};
  return columns;
}

const std::vector<std::string>& MeasurementQuantities() {
  static const std::vector<std::string> columns = {"L", "H", "D", "Y", "u_L", "u_H", "u_D", "u_Y"};
  return columns;
}

namespace {

ExperimentFolder FolderPaths(const std::string& directory) {
  namespace fs = std::filesystem;
  ExperimentFolder folder;
  folder.directory = directory;
  folder.json_path = (fs::path(directory) / kExperimentJsonFile).string();
  folder.csv_path = (fs::path(directory) / kMeasurementsCsvFile).string();
  return folder;
}

}  // namespace

ExperimentFolder ReadExperimentJson(const std::string& directory) {
  if (!std::filesystem::is_directory(directory)) throw InputError(directory, "is not an experiment folder");
  ExperimentFolder folder = FolderPaths(directory);
  folder.metadata = ReadJsonFile(folder.json_path);
  return folder;
}

ExperimentFolder ParseExperimentJson(const std::string& directory, const std::string& json_text) {
  ExperimentFolder folder = FolderPaths(directory);
  try {
    folder.metadata = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(folder.json_path, std::string("is not valid JSON: ") + e.what());
  }
  return folder;
}

CsvTable ParseMeasurements(const ExperimentFolder& folder, const std::string& csv_text) {
  std::istringstream in(csv_text);
  return ReadCsv(in, folder.csv_path);
}

std::optional<CsvTable> ReadMeasurements(const ExperimentFolder& folder) {
  if (!std::filesystem::exists(folder.csv_path)) return std::nullopt;
  return ReadCsvFile(folder.csv_path);
}

}  // namespace uphill
