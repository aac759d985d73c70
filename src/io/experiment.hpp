// Experiment: the folder lab technicians and the other tools share (formats uphill-experiment/1
// and /2, documented in data/README.md), read through experiment_folder.hpp:
//
//   EXP/experiment.json    apparatus constants, body, L convention, default standard
//                          uncertainties, operator, date, notes; values carry units ("300 mm");
//                          version 2: the camera file, the scene files by name, the options of
//                          the video analysis
//   EXP/measurements.csv   one row per trial: trial label, series, L, H (when it varies), D, Y,
//                          optional per-row uncertainties u_L, u_H, u_D, u_Y, a note; version 2:
//                          the trial's recording (`video`) and its scene's name (`scene`); Y may
//                          then be empty (it comes from the video's rest position); in either
//                          version, `excluded`: why the row is left out of the fits (blank: fitted)
//
// Paths in the folder (camera, scenes, videos) are relative '/'-separated paths that stay inside
// it (no "..", no absolute path: io/contained_directory.hpp); whether the file is there, and not
// a link out of the folder, is checked where it is read (app/video_trials.hpp).
//
// Every quantity comes from exactly one place: a column of measurements.csv (varies per row) or
// experiment.json's "apparatus" (constant). Units are stated, never guessed: a numeric column
// names its unit in its header (`D_mm`) or every cell carries one (`45 mm`).
//
// Loading never stops at the first bad row: a row that cannot be used keeps its error (file, row,
// column, rule) and the other rows are loaded. Problems with the folder, experiment.json or the
// header of measurements.csv throw InputError, as nothing can be analysed then.
#pragma once

#include <map>
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
  // Measured farthest rest position, m. Typed in measurements.csv (y_typed), or, when its cell is
  // empty in a row with a video, {0, 0} until the video's analysis fills it in
  // (app/video_trials.hpp); such a row is not usable before.
  Uncertain Y;
  bool y_typed = true;
  std::string video;  // version 2: the recording, relative to the folder ("" none)
  std::string scene;  // version 2: the name of its scene in Experiment::scenes ("" when no video)
  // Why the row is left out of the fits (its `excluded` cell, trimmed), or "" when it is fitted.
  // An excluded row is still checked, converted (X ± u(X)) and shown; only the fits skip it, so
  // excluding a row changes every fit exactly as deleting it would (report/analysis.hpp).
  std::string excluded;
  std::string error;  // one line: file, row, column, rule
  // The column the error is about (its quantity or label: "D", "Y", "trial", "video"…), or ""
  // when it names experiment.json or the whole record: where a page puts the mark.
  std::string error_column;
  // The row's length cells (L, H, D, Y, u_L…) that parse, SI, kept even when the row has an
  // error: a row check (report/row_check.hpp) can then say which value looks wrong.
  std::map<std::string, double> cells;

  bool HasY() const { return Y.value > 0.0; }
};

// Version 2's options of the trials' video analysis (`uphill analyse-track`'s, same defaults).
struct VideoAnalysisSettings {
  std::string fit = "g";  // "g" (an effective g) or "mu" (rolling resistance)
  double u_x = 0.5e-3;    // m, standard uncertainty of a tracked position, > 0
  double g = 9.80665;     // m/s², > 0
};

struct Experiment {
  std::string directory;
  nlohmann::json metadata;  // experiment.json as read
  int format_version = 1;   // 1 or 2
  std::string title, operator_name, date, notes;
  std::string camera;                         // version 2: camera file, relative ("" none)
  std::map<std::string, std::string> scenes;  // version 2: scene name -> scene file, relative
  VideoAnalysisSettings video_analysis;
  // Quantity -> the unit its header names ("mm" for `D_mm`); "" when every cell names its own.
  std::map<std::string, std::string> column_units;
  std::vector<ExperimentRow> rows;

  // Rows without an error and with a Y (typed, or filled in from the video), excluded or not.
  std::vector<const ExperimentRow*> UsableRows() const;
  // The rows' errors, and for a row whose Y is to come from its video but has not, why not.
  std::vector<std::string> Errors() const;
  bool HasVideos() const;  // some row names a video
};

// Throws InputError naming the file (and key) for a missing folder or file, malformed JSON, an
// unknown format version, unknown keys or columns, a version-2 key or column in a version-1 file,
// a path that leaves the folder, a quantity given twice, or a missing Y column. A bad `video` or
// `scene` cell, or an empty Y without a video, is the row's error.
Experiment LoadExperiment(const std::string& directory);

// The same from files already read (experiment_folder.hpp), e.g. a page's state written to text:
// `measurements` is the folder's measurements.csv. Throws as LoadExperiment does.
Experiment ParseExperiment(ExperimentFolder folder, const CsvTable& measurements);

}  // namespace uphill
