#include "server/experiment_state.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

#include "io/contained_directory.hpp"
#include "io/csv_table.hpp"
#include "io/experiment_folder.hpp"
#include "io/units.hpp"
#include "io/utf8.hpp"
#include "model/input_error.hpp"
#include "internal/state_text.hpp"

namespace uphill {

namespace internal {

// The page shows text only via textContent anyway; the rule is for the files' readers.
std::string CheckText(const nlohmann::json& j, const std::string& field, std::size_t max_length) {
  if (!j.is_string()) throw InputError(field, "must be a string");
  const std::string s = j.get<std::string>();
  if (InvalidUtf8At(s) != std::string_view::npos)
    throw InputError(field, "is not valid UTF-8 text (byte " + std::to_string(InvalidUtf8At(s) + 1) + ")");
  if (s.size() > max_length)
    throw InputError(field, "is longer than " + std::to_string(max_length) + " characters");
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) throw InputError(field, "must not contain control characters (e.g. a line break)");
  return s;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace internal

namespace {

using internal::CheckText;
using internal::Trim;
using nlohmann::json;
using nlohmann::ordered_json;

// experiment.json's keys in the order of data/README.md, whatever order a request or the journal
// (whose objects are sorted) has them in: the file on disk stays readable and stable.
ordered_json Canonical(const json& j) {
  if (!j.is_object()) return ordered_json(j);
  static const std::vector<std::string> order = {
      "format", "title", "operator", "date", "notes", "body", "apparatus", "uncertainties", "type", "L", "H", "D",
      "Y", "R", "a", "b", "h", "theta", "alpha", "rod_diameter", "L_convention", "camera", "scenes",
      "video_analysis"};
  ordered_json out = ordered_json::object();
  for (const std::string& key : order)
    if (j.contains(key)) out[key] = Canonical(j.at(key));
  for (const auto& [key, value] : j.items())
    if (!out.contains(key)) out[key] = Canonical(value);
  return out;
}

// A plain decimal number (what a technician types into a field whose unit the page shows).
std::string CheckNumber(const json& j, const std::string& field) {
  if (j.is_number()) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.15g", j.get<double>());
    return CheckNumber(json(std::string(buf)), field);
  }
  const std::string s = Trim(CheckText(j, field, kMaxNumberLength));
  if (s.empty()) return s;
  const char* begin = s.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end != begin + s.size() || !std::isfinite(v) || errno == ERANGE || s.find_first_of("xXpP") != std::string::npos ||
      s.find_first_of("nNiI") != std::string::npos)
    throw InputError(field, "must be a plain number in the experiment's unit (got \"" + s + "\")");
  return s;
}

// RFC 4180: quote a field that holds a separator, a quote or surrounding spaces.
std::string CsvCell(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos && Trim(s) == s) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string FormatNumber(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

}  // namespace

const std::vector<std::string>& RowQuantities() { return MeasurementQuantities(); }

void CheckRelativePath(const std::string& path, const std::string& field) {
  const std::string s = CheckText(json(path), field, kMaxPathLength);
  if (s.find('\\') != std::string::npos) throw InputError(field, "must use '/' between folders");
  try {
    SplitContainedPath(s);
  } catch (const InputError& e) {
    throw InputError(field, e.rule() + " (a path inside the experiment folder)");
  }
}

bool ExperimentState::UsesVideo() const {
  if (metadata.is_object())
    for (const std::string& key : ExperimentKeysOfVersion2())
      if (metadata.contains(key)) return true;
  return std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.video.empty() || !r.scene.empty(); });
}

const std::string& Row::Value(const std::string& quantity) const {
  static const std::string empty;
  const auto it = values.find(quantity);
  return it == values.end() ? empty : it->second;
}

std::vector<std::string> ExperimentState::Columns() const {
  std::vector<std::string> out;
  const json apparatus = metadata.is_object() && metadata.contains("apparatus") ? json(metadata.at("apparatus"))
                                                                               : json::object();
  const bool angles = apparatus.contains("theta") || apparatus.contains("alpha");
  for (const char* q : {"L", "H", "D"})
    if (!angles && !apparatus.contains(q)) out.push_back(q);
  out.push_back("Y");
  for (const char* q : {"u_L", "u_H", "u_D", "u_Y"}) {
    const std::string base = std::string(q).substr(2);
    if (base != "Y" && std::find(out.begin(), out.end(), base) == out.end()) continue;
    if (std::any_of(rows.begin(), rows.end(), [&](const Row& r) { return !r.Value(q).empty(); }))
      out.push_back(q);
  }
  return out;
}

std::vector<std::string> ExperimentState::RequiredQuantities(const Row* row) const {
  std::vector<std::string> out;
  if (row && !row->video.empty()) return out;
  for (const std::string& c : Columns())
    if (c.rfind("u_", 0) != 0) out.push_back(c);
  return out;
}

int ExperimentState::IndexOf(std::int64_t id) const {
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i].id == id) return static_cast<int>(i);
  return -1;
}

std::string ExperimentState::ExperimentJson() const {
  if (!UsesVideo() || !metadata.is_object()) return metadata.dump(2) + "\n";
  ordered_json j = metadata;
  j["format"] = kExperimentFormat2;
  return j.dump(2) + "\n";
}

std::string ExperimentState::MeasurementsCsv() const {
  const std::vector<std::string> columns = Columns();
  std::string out = "trial,series";
  // Appended piece by piece (`"," + c` trips GCC 12's false -Wrestrict).
  for (const std::string& c : columns) out.append(",").append(c).append("_").append(unit);
  const bool video = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.video.empty(); });
  const bool scene = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.scene.empty(); });
  // The exclusion column only once a row is excluded: a folder that never used it stays as it was.
  const bool excluded = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.excluded.empty(); });
  if (video) out += ",video";
  if (scene) out += ",scene";
  if (excluded) out.append(",").append(MeasurementExclusionColumn());
  out += ",note\n";
  for (const Row& r : rows) {
    out.append(CsvCell(r.trial)).append(",").append(CsvCell(r.series));
    for (const std::string& c : columns) out.append(",").append(CsvCell(r.Value(c)));
    if (video) out.append(",").append(CsvCell(r.video));
    if (scene) out.append(",").append(CsvCell(r.scene));
    if (excluded) out.append(",").append(CsvCell(r.excluded));
    out.append(",").append(CsvCell(r.note)).append("\n");
  }
  return out;
}

ordered_json ToJson(const Row& row) {
  ordered_json j;
  j["id"] = row.id;
  j["trial"] = row.trial;
  j["series"] = row.series;
  for (const std::string& q : RowQuantities())
    if (!row.Value(q).empty()) j[q] = row.Value(q);
  if (!row.video.empty()) j["video"] = row.video;
  if (!row.scene.empty()) j["scene"] = row.scene;
  if (!row.excluded.empty()) j["excluded"] = row.excluded;
  j["note"] = row.note;
  return j;
}

ordered_json ToJson(const ExperimentState& state) {
  ordered_json j;
  j["exists"] = state.exists;
  j["experiment"] = state.metadata.is_null() ? ordered_json::object() : state.metadata;
  j["unit"] = state.unit;
  j["next_id"] = state.next_id;
  j["rows"] = ordered_json::array();
  for (const Row& r : state.rows) j["rows"].push_back(ToJson(r));
  if (!state.files.empty()) j["files"] = state.files;
  return j;
}

namespace {
// A row as stored in the journal: trusted (it was validated when it was first accepted, or read
// from a file, where bad text is kept on purpose), so only its shape is checked.
Row RowFromJournal(const json& j) {
  if (!j.is_object()) throw InputError("journal row", "must be an object");
  Row r;
  r.id = j.at("id").get<std::int64_t>();
  r.trial = j.value("trial", "");
  r.series = j.value("series", "");
  r.note = j.value("note", "");
  r.video = j.value("video", "");
  r.scene = j.value("scene", "");
  r.excluded = j.value("excluded", "");
  for (const std::string& q : RowQuantities())
    if (j.contains(q)) r.values[q] = j.at(q).get<std::string>();
  return r;
}
}  // namespace

ExperimentState StateFromJson(const json& j) {
  try {
    ExperimentState s;
    s.exists = j.at("exists").get<bool>();
    s.metadata = Canonical(j.at("experiment"));
    if (s.metadata.empty()) s.metadata = ordered_json();
    s.unit = j.at("unit").get<std::string>();
    s.next_id = j.at("next_id").get<std::int64_t>();
    for (const json& r : j.at("rows")) s.rows.push_back(RowFromJournal(r));
    if (j.contains("files")) s.files = j.at("files").get<std::map<std::string, std::string>>();
    return s;
  } catch (const json::exception& e) {
    throw InputError("journal snapshot", e.what());
  }
}

void ValidateUnit(const std::string& unit) {
  if (unit != "mm" && unit != "cm" && unit != "m" && unit != "in")
    throw InputError("unit", "must be mm, cm, m or in (got \"" + unit.substr(0, 16) + "\")");
}

Row ValidateRow(const json& j, const ExperimentState& state, RowStage stage) {
  if (!j.is_object()) throw InputError("row", "must be a JSON object");
  Row r;
  std::set<std::string> allowed = {"id", "trial", "series", "note", "video", "scene", "excluded"};
  for (const std::string& q : RowQuantities()) allowed.insert(q);
  for (const auto& [key, value] : j.items())
    if (!allowed.count(key)) throw InputError("row." + key.substr(0, 32), "unknown field");
  r.trial = Trim(CheckText(j.value("trial", json("")), "row.trial", kMaxLabelLength));
  if (r.trial.empty()) throw InputError("row.trial", "is empty: every trial needs a label");
  r.series = Trim(CheckText(j.value("series", json("")), "row.series", kMaxLabelLength));
  r.note = CheckText(j.value("note", json("")), "row.note", kMaxNoteLength);
  // Why the row is left out of the fits ("" : fitted).
  r.excluded = Trim(CheckText(j.value("excluded", json("")), "row.excluded", kMaxNoteLength));
  r.video = Trim(CheckText(j.value("video", json("")), "row.video", kMaxPathLength));
  if (!r.video.empty()) CheckRelativePath(r.video, "row.video");
  r.scene = Trim(CheckText(j.value("scene", json("")), "row.scene", kMaxLabelLength));
  if (!r.scene.empty()) {
    const bool known = state.metadata.is_object() && state.metadata.contains("scenes") &&
                       state.metadata.at("scenes").contains(r.scene);
    if (!known) throw InputError("row.scene", "names no scene of the experiment (\"" + r.scene + "\")");
  }
  for (const std::string& q : RowQuantities()) {
    if (!j.contains(q) || j.at(q).is_null()) continue;
    const std::string v = CheckNumber(j.at(q), "row." + q);
    if (!v.empty()) r.values[q] = v;
  }
  for (const std::string& q : state.RequiredQuantities(&r))
    if (r.Value(q).empty() && !(q == "Y" && stage == RowStage::kDraft))
      throw InputError("row." + q, "is missing (a number in " + state.unit + ")");
  return r;
}

std::vector<Row> ValidateRows(const json& j, const ExperimentState& state) {
  if (!j.is_array() || j.empty()) throw InputError("rows", "must be a non-empty list of rows");
  if (state.rows.size() + j.size() > kMaxRows)
    throw InputError("rows", "at most " + std::to_string(kMaxRows) + " rows per experiment");
  std::vector<Row> rows;
  std::vector<InputError> refused;
  for (std::size_t i = 0; i < j.size(); ++i) try {
      rows.push_back(ValidateRow(j[i], state));
    } catch (const InputError& e) {
      const std::string field = e.quantity().rfind("row.", 0) == 0 ? e.quantity().substr(4) : e.quantity();
      refused.emplace_back("rows[" + std::to_string(i) + "]." + field, e.rule());
    }
  if (!refused.empty()) throw FieldErrors(std::move(refused));
  return rows;
}

namespace {

// A quantity the new experiment.json makes a constant of the apparatus (or unused: the rails
// given as angles) would drop its column, and every value measured in it, from measurements.csv.
// Measured data is never dropped: refused while any row has a value in that column.
void RefuseDroppingMeasuredColumns(const ExperimentState& state, const ordered_json& metadata) {
  ExperimentState next;
  next.metadata = metadata;
  const std::vector<std::string> kept = next.Columns();
  for (const std::string& q : RowQuantities()) {
    const std::string base = q.rfind("u_", 0) == 0 ? q.substr(2) : q;
    if (std::find(kept.begin(), kept.end(), base) != kept.end()) continue;
    const auto measured = std::count_if(state.rows.begin(), state.rows.end(),
                                        [&](const Row& r) { return !r.Value(q).empty(); });
    if (measured == 0) continue;
    const bool constant = metadata.contains("apparatus") && metadata.at("apparatus").contains(base);
    throw InputError(constant ? "apparatus." + base : "apparatus",
                     (constant ? std::string("would make ") + base + " a constant"
                               : std::string("gives the rails as angles, which leaves no column for ") + base) +
                         ", but " + std::to_string(measured) + " row(s) have a measured " + q +
                         ": clear those cells first (measured data is never dropped)");
  }
}

}  // namespace

json ApplyOperation(ExperimentState& state, const json& op) {
  const std::string type = op.at("type").get<std::string>();
  if (type == "snapshot") {
    json inverse = {{"type", "snapshot"}, {"state", ToJson(state)}};
    state = StateFromJson(op.at("state"));
    return inverse;
  }
  if (type == "meta") {
    const std::string unit = op.at("unit").get<std::string>();
    ValidateUnit(unit);
    if (unit != state.unit && !state.rows.empty())
      throw InputError("unit", "cannot change once rows exist (their numbers were typed in " + state.unit + ")");
    json inverse = state.exists ? json{{"type", "meta"}, {"experiment", state.metadata}, {"unit", state.unit}}
                                : json{{"type", "snapshot"}, {"state", ToJson(state)}};
    ordered_json metadata = Canonical(op.at("experiment"));
    RefuseDroppingMeasuredColumns(state, metadata);
    state.metadata = std::move(metadata);
    state.unit = unit;
    state.exists = true;
    return inverse;
  }
  if (!state.exists) throw InputError("experiment", "does not exist yet: create it first");
  if (type == "put") {
    Row row = RowFromJournal(op.at("row"));
    const int index = state.IndexOf(row.id);
    if (index >= 0) {
      json inverse = {{"type", "put"}, {"row", ToJson(state.rows[index])}, {"index", index}};
      state.rows[index] = std::move(row);
      return inverse;
    }
    if (state.rows.size() >= kMaxRows)
      throw InputError("rows", "at most " + std::to_string(kMaxRows) + " rows per experiment");
    if (row.id < 1) throw InputError("row.id", "must be >= 1");
    const std::int64_t at = std::clamp<std::int64_t>(op.value("index", static_cast<std::int64_t>(state.rows.size())), 0,
                                                     static_cast<std::int64_t>(state.rows.size()));
    state.next_id = std::max(state.next_id, row.id + 1);
    json inverse = {{"type", "delete"}, {"id", row.id}};
    state.rows.insert(state.rows.begin() + at, std::move(row));
    return inverse;
  }
  if (type == "file") {
    const std::string role = op.at("role").get<std::string>();
    const std::string path = op.at("path").get<std::string>();
    const std::string name = op.value("name", "");
    CheckRelativePath(path, "path");
    if (role != "scene" && role != "camera") throw InputError("role", "must be scene or camera");
    ordered_json& meta = state.metadata;
    // The inverse names the file the name pointed to before, with its text (or removes the name).
    std::string old_path = path;
    if (role == "camera" && meta.contains("camera")) old_path = meta.at("camera").get<std::string>();
    if (role == "scene" && meta.contains("scenes") && meta.at("scenes").contains(name))
      old_path = meta.at("scenes").at(name).get<std::string>();
    json inverse = {{"type", "file"}, {"role", role}, {"name", name}, {"path", old_path}, {"content", nullptr}};
    if (const auto it = state.files.find(old_path); it != state.files.end()) inverse["content"] = it->second;
    if (op.at("content").is_null()) {
      state.files.erase(path);
      if (role == "camera") meta.erase("camera");
      else if (meta.contains("scenes")) {
        meta["scenes"].erase(name);
        if (meta["scenes"].empty()) meta.erase("scenes");
      }
    } else {
      state.files[path] = op.at("content").get<std::string>();
      if (role == "camera") meta["camera"] = path;
      else meta["scenes"][name] = path;
    }
    state.metadata = Canonical(meta);
    return inverse;
  }
  if (type == "batch") {
    const json& ops = op.at("ops");
    if (!ops.is_array()) throw InputError("batch", "ops must be a list");
    ExperimentState next = state;  // all or nothing
    json inverses = json::array();
    for (const json& o : ops) {
      if (o.at("type") == "snapshot" || o.at("type") == "meta" || o.at("type") == "batch")
        throw InputError("batch", "holds row and file changes only");
      inverses.insert(inverses.begin(), ApplyOperation(next, o));
    }
    state = std::move(next);
    return {{"type", "batch"}, {"ops", inverses}};
  }
  if (type == "delete") {
    const std::int64_t id = op.at("id").get<std::int64_t>();
    const int index = state.IndexOf(id);
    if (index < 0) throw InputError("row " + std::to_string(id), "does not exist (deleted meanwhile?)");
    json inverse = {{"type", "put"}, {"row", ToJson(state.rows[index])}, {"index", index}};
    state.rows.erase(state.rows.begin() + index);
    return inverse;
  }
  throw InputError("operation", "unknown type \"" + type.substr(0, 32) + "\"");
}

ExperimentState LoadStateFromFiles(const std::string& directory) {
  const ExperimentFolder folder = ReadExperimentJson(directory);
  return StateFromFolder(folder, ReadMeasurements(folder));
}

ExperimentState StateFromFolder(const ExperimentFolder& folder, const std::optional<CsvTable>& measurements) {
  ExperimentState state;
  try {
    state.metadata = ValidateMetadata(folder.metadata);
  } catch (const InputError& e) {
    throw InputError(folder.json_path + ": " + e.quantity(), e.rule());
  }
  // Keep what ValidateMetadata would drop only for being empty: the file is the authority here.
  state.metadata = Canonical(folder.metadata);
  state.exists = true;
  if (!measurements) return state;
  const CsvTable& table = *measurements;
  const int y = [&] {
    for (std::size_t i = 0; i < table.header.size(); ++i)
      if (SplitUnitSuffix(table.header[i]).first == "Y") return static_cast<int>(i);
    return -1;
  }();
  if (y >= 0) {
    const std::string suffix = SplitUnitSuffix(table.header[y]).second;
    if (suffix == "mm" || suffix == "cm" || suffix == "m" || suffix == "in") state.unit = suffix;
  }
  for (const CsvRow& csv_row : table.rows) {
    Row r;
    r.id = state.next_id++;
    for (std::size_t i = 0; i < table.header.size() && i < csv_row.cells.size(); ++i) {
      const auto [base, suffix] = SplitUnitSuffix(table.header[i]);
      const std::string& cell = csv_row.cells[i];
      if (base == "trial") r.trial = cell;
      else if (base == "series") r.series = cell;
      else if (base == "note") r.note = cell;
      else if (base == "video") r.video = Trim(cell);
      else if (base == "scene") r.scene = Trim(cell);
      else if (base == MeasurementExclusionColumn()) r.excluded = Trim(cell);
      else if (std::find(RowQuantities().begin(), RowQuantities().end(), base) != RowQuantities().end()) {
        const std::string text = Trim(cell);
        if (text.empty()) continue;
        if (suffix == state.unit) {
          r.values[base] = text;
          continue;
        }
        try {  // another unit (a suffix or a unit in the cell): re-express in the state's unit
          const double si = ParseQuantity(text, Dimension::kLength, base, suffix);
          r.values[base] = FormatNumber(ToUnit(si, Dimension::kLength, state.unit));
        } catch (const InputError&) {
          r.values[base] = text;  // kept as it is: the row's check will say what is wrong
        }
      }
    }
    state.rows.push_back(std::move(r));
  }
  return state;
}

}  // namespace uphill
