// ExperimentState: an experiment folder (data/README.md, uphill-experiment/1) as the page edits
// it, and the operations that change it — the unit of the journal (experiment_store.hpp).
//
// Numbers are kept as the technician typed them: plain decimal text in the experiment's one
// measurement unit (`unit`, e.g. "mm"; it becomes the CSV headers' suffix, `L_mm`). Keeping the
// text, not a double, means the file on disk shows exactly what was entered, and a reload gives
// the same text back.
//
// Operations are JSON objects (so the journal stores them verbatim):
//   {"type":"snapshot","state":{...}}                  the whole state (ToJson below)
//   {"type":"meta","experiment":{...},"unit":"mm"}     replace experiment.json and the unit
//   {"type":"put","row":{...},"index":i}               insert (new id) or replace (same id) a row
//   {"type":"delete","id":n}                           remove a row
//   {"type":"batch","ops":[op,...]}                    the operations in order, as one change
//                                                      (rows pasted or imported: one undo)
//   {"type":"file","role":"scene"|"camera","name":s,"path":p,"content":text|null}
//                                                      a calibration file of the folder (format
//                                                      uphill-experiment/2): its text, and its
//                                                      name in experiment.json (`scenes`.s or
//                                                      `camera`); null removes the name
// ApplyOperation returns the operation that undoes it, so undo is itself just an operation.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/csv_table.hpp"
#include "io/experiment_folder.hpp"
#include "model/input_error.hpp"

namespace uphill {

// Request limits (also the server's): a page that asks for more is not a lab notebook.
inline constexpr std::size_t kMaxRows = 5000;
inline constexpr std::size_t kMaxLabelLength = 64;   // trial, series
inline constexpr std::size_t kMaxNoteLength = 2000;  // note, notes paragraphs, title
inline constexpr std::size_t kMaxNumberLength = 32;

// The quantities a row may carry: the crossbar measurements, Y, and per-row uncertainties.
const std::vector<std::string>& RowQuantities();  // L, H, D, Y, u_L, u_H, u_D, u_Y

// A folder is written as uphill-experiment/1 until it uses a feature of version 2 (io's
// ExperimentKeysOfVersion2, a row's video or scene), then as kExperimentFormat2.
inline constexpr std::size_t kMaxPathLength = 240;  // a video's or calibration file's path

// A path relative to the experiment folder, as experiment.json and measurements.csv name files:
// '/'-separated, no empty, "." or ".." component, not absolute, no control characters or
// backslashes, at most kMaxPathLength bytes. Throws InputError(field, rule).
void CheckRelativePath(const std::string& path, const std::string& field);

struct Row {
  std::int64_t id = 0;  // assigned by the store, stable across edits; never reused
  std::string trial, series, note;
  std::string video, scene;  // the trial's recording (a path in the folder) and its scene's name
  std::string excluded;      // why the row is left out of the fits ("" : fitted), measurements.csv's `excluded`
  std::map<std::string, std::string> values;  // quantity -> plain number text in `unit`

  // The value as typed, or "" when absent.
  const std::string& Value(const std::string& quantity) const;
};

struct ExperimentState {
  bool exists = false;              // experiment.json has been written (or will be, on replay)
  nlohmann::ordered_json metadata;  // experiment.json, validated (ValidateMetadata)
  std::string unit = "mm";          // of every length in measurements.csv
  std::vector<Row> rows;
  std::int64_t next_id = 1;
  // The calibration files the state owns (path in the folder -> text), written with the others.
  std::map<std::string, std::string> files;

  // Whether the folder uses a feature of uphill-experiment/2 (a video key or column).
  bool UsesVideo() const;

  // The measured quantities that are columns (vary per row): L, H, D unless experiment.json's
  // apparatus gives them (or gives θ/α), then Y; then the u_ columns some row uses.
  std::vector<std::string> Columns() const;
  // The quantities a row must give: Columns() without the u_ ones. A row with a video must give
  // none: its Y comes from the video's rest position, and a trial created from its recording
  // has no setting yet (the row check flags the empty cells until the technician types them).
  std::vector<std::string> RequiredQuantities(const Row* row = nullptr) const;
  // Index into rows, or -1.
  int IndexOf(std::int64_t id) const;

  // The files' contents, exactly as written to disk.
  std::string ExperimentJson() const;
  std::string MeasurementsCsv() const;
};

nlohmann::ordered_json ToJson(const Row& row);
nlohmann::ordered_json ToJson(const ExperimentState& state);
ExperimentState StateFromJson(const nlohmann::json& json);  // of a snapshot; throws InputError

// Several rule violations of one request at once (a form's every wrong field, an import's every
// refused row), so the page can name and highlight them all: `errors` holds each (field, rule);
// what() and quantity() are the first one's.
class FieldErrors : public InputError {
 public:
  explicit FieldErrors(std::vector<InputError> errors);
  const std::vector<InputError>& errors() const { return errors_; }

 private:
  std::vector<InputError> errors_;
};

// Whether a row is one to save, or a draft being typed (the page shows X as soon as the setting
// is complete, before Y is typed).
enum class RowStage { kSaved, kDraft };

// A row from a request: checks types, lengths, control characters, that every value is a plain
// finite decimal number, and that the quantities the experiment needs are there (a draft may
// leave Y empty). The id is not read. Throws InputError("row.<field>", rule).
Row ValidateRow(const nlohmann::json& json, const ExperimentState& state, RowStage stage = RowStage::kSaved);

// Rows from a request (pasted or imported): each validated as ValidateRow does. Throws
// FieldErrors naming every refused row and its field ("rows[3].D"), so nothing is half-added.
std::vector<Row> ValidateRows(const nlohmann::json& json, const ExperimentState& state);

// experiment.json from a request: known keys only (as LoadExperiment), strings with units
// that parse, a body type, lengths and counts bounded. Sets "format". Throws InputError, or
// FieldErrors when several fields are wrong (every one is named, not just the first).
nlohmann::ordered_json ValidateMetadata(const nlohmann::json& json);
// "mm", "cm", "m" or "in". Throws InputError otherwise.
void ValidateUnit(const std::string& unit);

// Applies `op` (format above) to `state` and returns its inverse. Throws InputError (and leaves
// `state` unchanged) when the operation does not fit the state: unknown row id, unit change
// while rows exist, too many rows.
nlohmann::json ApplyOperation(ExperimentState& state, const nlohmann::json& op);

// Reads an experiment folder written by hand or by another program (any units in the CSV) into
// a state; lengths are re-expressed in the Y column's unit (default mm). Rows that cannot be read
// keep their raw text, so nothing is dropped. Throws InputError for a bad experiment.json or a
// missing/unreadable measurements.csv header.
ExperimentState LoadStateFromFiles(const std::string& directory);

// The same from the folder's files as read by io/experiment_folder.hpp (`measurements` absent: no
// measurements.csv yet): the store reads them itself, through a contained folder.
ExperimentState StateFromFolder(const ExperimentFolder& folder, const std::optional<CsvTable>& measurements);

}  // namespace uphill
