// ExperimentFolder: the one reader of an experiment folder's files (formats uphill-experiment/1
// and /2, data/README.md), and the one place that names them, the keys of experiment.json and the columns
// of measurements.csv. LoadExperiment (experiment.hpp: the rows as configurations, for analysis)
// and the server's editable state (server/experiment_state.hpp: the rows as typed) both read the
// folder through it; the server writes the files it names.
//
//   EXP/experiment.json    read whole (ReadJsonFile); its keys are checked by the callers, each
//                          with its own strictness (analysis vs. the page's edits)
//   EXP/measurements.csv   read whole (ReadCsvFile); may be absent in a folder the page has just
//                          created
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "io/csv_table.hpp"

namespace uphill {

// Version 1: typed rows only. Version 2 adds the trials' recordings: experiment.json's `camera`,
// `scenes` and `video_analysis`, measurements.csv's `video` and `scene` columns, and an empty Y in
// a row with a video (Y then comes from the video's rest position). A version-1 file that uses any
// of these is refused ("needs format uphill-experiment/2"). A writer keeps a folder at version 1
// until it uses a version-2 feature (kExperimentFormat: what a new folder is written as).
inline constexpr const char* kExperimentFormat1 = "uphill-experiment/1";
inline constexpr const char* kExperimentFormat2 = "uphill-experiment/2";
inline constexpr const char* kExperimentFormat = kExperimentFormat1;
inline constexpr const char* kExperimentJsonFile = "experiment.json";
inline constexpr const char* kMeasurementsCsvFile = "measurements.csv";
// The folder's cache of the trials' tracked videos (app/video_trials.hpp): never an output's place.
inline constexpr const char* kVideoCacheFolder = ".uphill-cache";

// The keys experiment.json may have: at the top, in "body", in "apparatus" (constants of the
// apparatus), in "uncertainties" (default standard uncertainties) and in "video_analysis" (the
// options of `uphill analyse-track` for the trials' recordings).
const std::set<std::string>& ExperimentKeys();    // format title operator date notes body apparatus
                                                  // uncertainties, and (version 2) camera scenes video_analysis
const std::set<std::string>& ExperimentKeysOfVersion2();  // camera scenes video_analysis
const std::set<std::string>& BodyKeys();          // type R a b h
const std::set<std::string>& ApparatusKeys();     // L H D theta alpha rod_diameter L_convention
const std::set<std::string>& UncertaintyKeys();   // L H D Y R a b h theta alpha rod_diameter
const std::set<std::string>& VideoAnalysisKeys(); // fit u_x g

// The columns of measurements.csv: the label columns, then the numeric quantities (a length unit
// in the header, `L_mm`, or in every cell), in the order the server writes them.
const std::vector<std::string>& MeasurementLabelColumns();  // trial series note
const std::vector<std::string>& MeasurementVideoColumns();  // video scene (version 2: text cells)
// "excluded" (either version, optional): a text cell; non-blank leaves the row out of the fits,
// its text being the reason (data/README.md).
const std::string& MeasurementExclusionColumn();
const std::vector<std::string>& MeasurementQuantities();    // L H D Y u_L u_H u_D u_Y

struct ExperimentFolder {
  std::string directory;
  std::string json_path, csv_path;  // directory/experiment.json, directory/measurements.csv
  nlohmann::json metadata;          // experiment.json as parsed, not yet checked
};

// The folder's paths and experiment.json. Throws InputError naming the folder when it is not a
// folder, or the file when it cannot be opened or is not valid JSON.
ExperimentFolder ReadExperimentJson(const std::string& directory);

// measurements.csv of the folder, or nullopt when the file does not exist. Throws InputError
// naming the file when it exists but cannot be read or is malformed CSV.
std::optional<CsvTable> ReadMeasurements(const ExperimentFolder& folder);

// The same from the files' contents, for a reader that opened them itself (the server reads them
// through ContainedDirectory, which refuses links): `json_text` is experiment.json of
// `directory`, `csv_text` its measurements.csv. Messages name the files as the path readers do.
// Throw InputError when experiment.json is not valid JSON or measurements.csv malformed CSV.
ExperimentFolder ParseExperimentJson(const std::string& directory, const std::string& json_text);
CsvTable ParseMeasurements(const ExperimentFolder& folder, const std::string& csv_text);

}  // namespace uphill
