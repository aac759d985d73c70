// Experiment: the folder lab technicians and the other tools share (format uphill-experiment/1,
// documented in data/README.md), read through experiment_folder.hpp:
//
//   EXP/experiment.json    apparatus constants, body, L convention, default standard
//                          uncertainties, operator, date, notes; values carry units ("300 mm")
//   EXP/measurements.csv   one row per trial: trial label, series, L, H (when it varies), D, Y,
//                          optional per-row uncertainties u_L, u_H, u_D, u_Y, a note
//
// Every quantity comes from exactly one place: a column of measurements.csv (varies per row) or
// experiment.json's "apparatus" (constant). Units are stated, never guessed: a numeric column
// names its unit in its header (`D_mm`) or every cell carries one (`45 mm`).
//
// Loading never stops at the first bad row: a row that cannot be used keeps its error (file, row,
// column, rule) and the other rows are loaded. Problems with the folder, experiment.json or the
// header of measurements.csv throw InputError, as nothing can be analysed then.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "io/experiment_folder.hpp"

namespace uphill {

struct ExperimentRow {
  int row = 0;  // spreadsheet row in measurements.csv (header = 1)
  std::string trial, series, note;
  std::optional<Configuration> configuration;  // empty when error is set
  Uncertain Y;                                 // measured farthest rest position, m
  std::string error;                           // one line: file, row, column, rule
};

struct Experiment {
  std::string directory;
  nlohmann::json metadata;  // experiment.json as read
  std::string title, operator_name, date, notes;
  std::vector<ExperimentRow> rows;

  std::vector<const ExperimentRow*> UsableRows() const;
  std::vector<std::string> Errors() const;
};

// Throws InputError naming the file (and key) for a missing folder or file, malformed JSON, an
// unknown format version, unknown keys or columns, a quantity given twice, or a missing Y column.
Experiment LoadExperiment(const std::string& directory);

}  // namespace uphill
