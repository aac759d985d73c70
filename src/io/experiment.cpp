#include "io/experiment.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "io/contained_directory.hpp"
#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"

namespace uphill {
namespace {

using nlohmann::json;

bool Contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

bool IsColumn(const std::string& name) {
  return Contains(MeasurementLabelColumns(), name) || Contains(MeasurementVideoColumns(), name) ||
         Contains(MeasurementQuantities(), name) || name == MeasurementExclusionColumn();
}

std::string Trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  return first == std::string::npos ? "" : s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

std::string NeedsVersion2() { return std::string("needs format ") + kExperimentFormat2; }

// A JSON value for a message: scalars as written, arrays and objects by their type only. Dumping
// them recursed once per nesting level: a value nested 2·10^5 deep (a 400 KB file) overflowed
// the stack (tests/fuzz/fuzz_experiment runs on a small stack to catch this).
std::string Shown(const json& j) {
  return j.is_structured() ? std::string("an ") + j.type_name() : j.dump();
}

std::string Text(const json& j, const std::string& context) {
  if (j.is_string()) return j.get<std::string>();
  throw InputError(context, "must be a string with a unit, e.g. \"300 mm\" (got " + Shown(j) + ")");
}


void CheckKeys(const json& object, const std::set<std::string>& allowed, const std::string& context) {
  if (!object.is_object()) throw InputError(context, "must be a JSON object");
  for (const auto& [key, value] : object.items())
    if (!allowed.count(key)) throw InputError(context + "." + key, "unknown key");
}

std::string OptionalString(const json& meta, const std::string& key, const std::string& file) {
  if (!meta.contains(key)) return "";
  const json& v = meta.at(key);
  if (v.is_string()) return v.get<std::string>();
  if (v.is_array()) {  // notes may be a list of paragraphs
    std::string joined;
    for (const json& p : v) joined += (joined.empty() ? "" : "\n") + Text(p, file + ": " + key);
    return joined;
  }
  throw InputError(file + ": " + key, "must be a string");
}

// A path of experiment.json or measurements.csv inside the folder (`context` names where it is).
std::string ContainedPath(const std::string& text, const std::string& context) {
  try {
    SplitContainedPath(text);
  } catch (const InputError& e) {
    throw InputError(context, "'" + text + "' " + e.rule());
  }
  return text;
}

// Version 2's keys of experiment.json into `e` (nothing when absent).
void ReadVideoKeys(const json& meta, const std::string& json_path, Experiment* e) {
  if (meta.contains("camera"))
    e->camera = ContainedPath(Text(meta.at("camera"), json_path + ": camera"), json_path + ": camera");
  if (meta.contains("scenes")) {
    const json& scenes = meta.at("scenes");
    if (!scenes.is_object() || scenes.empty())
      throw InputError(json_path + ": scenes", "must be an object of scene name -> scene file, with at least one");
    for (const auto& [name, file] : scenes.items()) {
      const std::string where = json_path + ": scenes." + name;
      if (name.empty() || name.find_first_of(",\"\r\n") != std::string::npos)
        throw InputError(where, "a scene name must be non-empty text without commas, quotes or line breaks");
      e->scenes[name] = ContainedPath(Text(file, where), where);
    }
  }
  if (meta.contains("video_analysis")) {
    const json& options = meta.at("video_analysis");
    CheckKeys(options, VideoAnalysisKeys(), json_path + ": video_analysis");
    VideoAnalysisSettings& v = e->video_analysis;
    if (options.contains("fit")) {
      v.fit = Text(options.at("fit"), json_path + ": video_analysis.fit");
      if (v.fit != "g" && v.fit != "mu")
        throw InputError(json_path + ": video_analysis.fit",
                         "must be \"g\" (an effective g) or \"mu\" (rolling resistance), got '" + v.fit + "'");
    }
    if (options.contains("u_x")) {
      const std::string where = json_path + ": video_analysis.u_x";
      v.u_x = ParseQuantity(Text(options.at("u_x"), where), Dimension::kLength, where);
      RequirePositiveLength(where, v.u_x);
    }
    if (options.contains("g")) {
      const std::string where = json_path + ": video_analysis.g";
      v.g = ParseQuantity(Text(options.at("g"), where), Dimension::kAcceleration, where);
      RequireGravity(where, v.g);
    }
  }
}

}  // namespace

std::vector<const ExperimentRow*> Experiment::UsableRows() const {
  std::vector<const ExperimentRow*> out;
  for (const auto& r : rows)
    if (r.error.empty() && r.HasY()) out.push_back(&r);
  return out;
}

std::vector<std::string> Experiment::Errors() const {
  std::vector<std::string> out;
  for (const auto& r : rows)
    if (!r.error.empty()) {
      out.push_back(r.error);
    } else if (!r.HasY()) {
      out.push_back(directory + "/" + kMeasurementsCsvFile + ", row " + std::to_string(r.row) +
                    ", column Y: is empty and the video '" + r.video +
                    "' has not been analysed (`uphill report` analyses the videos)");
    }
  return out;
}

bool Experiment::HasVideos() const {
  return std::any_of(rows.begin(), rows.end(), [](const ExperimentRow& r) { return !r.video.empty(); });
}

namespace {

// The `video` and `scene` cells of a row (version 2) into `row`; InputError naming the cell.
void ReadVideoCells(const Experiment& e, const CsvTable& table, int row_number, const std::string& video,
                    const std::string& scene, ExperimentRow* row) {
  const std::string video_context = CellContext(table, row_number, "video");
  const std::string scene_context = CellContext(table, row_number, "scene");
  if (video.empty()) {
    if (!scene.empty()) throw InputError(scene_context, "names a scene but the row has no video");
    return;
  }
  row->video = ContainedPath(video, video_context);
  if (e.camera.empty())
    throw InputError(video_context, "a video needs the camera file: experiment.json has no \"camera\"");
  if (e.scenes.empty())
    throw InputError(video_context, "a video needs a scene file: experiment.json has no \"scenes\"");
  if (scene.empty()) {
    if (e.scenes.size() != 1)
      throw InputError(scene_context, "is empty: name one of the " + std::to_string(e.scenes.size()) +
                                          " scenes of experiment.json");
    row->scene = e.scenes.begin()->first;
  } else {
    if (!e.scenes.count(scene)) throw InputError(scene_context, "'" + scene + "' is not a key of experiment.json's scenes");
    row->scene = scene;
  }
}

}  // namespace

Experiment LoadExperiment(const std::string& directory) {
  ExperimentFolder folder = ReadExperimentJson(directory);
  // Required here (the page may create a folder before its first row; an analysis needs rows).
  const CsvTable table = ReadCsvFile(folder.csv_path);
  return ParseExperiment(std::move(folder), table);
}

Experiment ParseExperiment(ExperimentFolder folder, const CsvTable& table) {
  const std::string& json_path = folder.json_path;
  const std::string& csv_path = folder.csv_path;
  Experiment e;
  e.directory = folder.directory;
  e.metadata = std::move(folder.metadata);  // moved: a copy recurses once per nesting level
  const json& meta = e.metadata;
  CheckKeys(meta, ExperimentKeys(), json_path);
  if (meta.contains("format") && meta.at("format") == kExperimentFormat2) {
    e.format_version = 2;
  } else if (!meta.contains("format") || meta.at("format") != kExperimentFormat1) {
    throw InputError(json_path + ": format",
                     std::string("must be \"") + kExperimentFormat1 + "\" or \"" + kExperimentFormat2 + "\" (got " +
                         (meta.contains("format") ? Shown(meta.at("format")) : "nothing") + ")");
  }
  if (e.format_version == 1)
    for (const std::string& key : ExperimentKeysOfVersion2())
      if (meta.contains(key)) throw InputError(json_path + ": " + key, NeedsVersion2());
  ReadVideoKeys(meta, json_path, &e);
  e.title = OptionalString(meta, "title", json_path);
  e.operator_name = OptionalString(meta, "operator", json_path);
  e.date = OptionalString(meta, "date", json_path);
  e.notes = OptionalString(meta, "notes", json_path);
  if (!meta.contains("body")) throw InputError(json_path + ": body", "is missing");
  const json& body = meta.at("body");
  CheckKeys(body, BodyKeys(), json_path + ": body");
  // Without this check body.at("type") below threw json::out_of_range (found by fuzzing).
  if (!body.contains("type"))
    throw InputError(json_path + ": body.type", "is missing (sphere, spheroid or double-cone)");
  // References, not copies (meta.value() copied): copying a json value recurses once per
  // nesting level.
  static const json kNone = json::object();
  const json& apparatus = meta.contains("apparatus") ? meta.at("apparatus") : kNone;
  CheckKeys(apparatus, ApparatusKeys(), json_path + ": apparatus");
  const json& defaults = meta.contains("uncertainties") ? meta.at("uncertainties") : kNone;
  CheckKeys(defaults, UncertaintyKeys(), json_path + ": uncertainties");
  // Every value of these objects is a string, checked now and not only when a row looks it up:
  // an unused value stays in `metadata`, which fit.json copies and dumps, recursively (a deeply
  // nested value overflowed the stack).
  for (const auto& [object, name] : {std::pair<const json*, const char*>{&body, "body"},
                                     {&apparatus, "apparatus"}, {&defaults, "uncertainties"}})
    for (const auto& [key, value] : object->items()) Text(value, json_path + ": " + name + "." + key);

  std::map<std::string, int> column;  // quantity -> column index
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string base = SplitUnitSuffix(table.header[i]).first;
    const std::string where = CellContext(table, 1, table.header[i]);
    if (!IsColumn(base)) throw InputError(where, "unknown column (see data/README.md)");
    if (e.format_version == 1 && Contains(MeasurementVideoColumns(), base)) throw InputError(where, NeedsVersion2());
    if ((Contains(MeasurementVideoColumns(), base) || base == MeasurementExclusionColumn()) && base != table.header[i])
      throw InputError(where, "'" + base + "' is text: its header has no unit");
    if (!column.emplace(base, static_cast<int>(i)).second)
      throw InputError(where, "gives '" + base + "' a second time");
    if (Contains(MeasurementQuantities(), base)) e.column_units[base] = SplitUnitSuffix(table.header[i]).second;
    if (apparatus.contains(base))
      throw InputError(where, "'" + base + "' is also a constant in experiment.json (apparatus." + base +
                                  "): give it in one place only");
  }
  for (const char* required : {"trial", "Y"})
    if (!column.count(required) && !(std::string(required) == "Y" && column.count("video")))
      throw InputError(csv_path + ", row 1", std::string("column '") + required + "' is missing");
  if (table.rows.empty()) throw InputError(csv_path, "has a header but no data rows");

  std::set<std::string> trials;
  for (const CsvRow& csv_row : table.rows) {
    ExperimentRow row;
    row.row = csv_row.row;
    const auto cell = [&](const std::string& name) -> std::string {
      auto it = column.find(name);
      return it == column.end() || !csv_row.error.empty() ? "" : csv_row.cells[it->second];
    };
    // Which column an error names: its cell's context, as CellContext writes it.
    std::map<std::string, std::string> column_of_context;
    for (const auto& [name, index] : column) column_of_context[CellContext(table, row.row, table.header[index])] = name;
    if (csv_row.error.empty())
      for (const std::string& q : MeasurementQuantities())
        if (const auto it = column.find(q); it != column.end()) try {
            const std::string& text = csv_row.cells[it->second];
            if (text.find_first_not_of(" \t") != std::string::npos)
              row.cells[q] = ParseQuantity(text, Dimension::kLength, q, SplitUnitSuffix(table.header[it->second]).second);
          } catch (const InputError&) {
            // the configuration's parse below names it
          }
    try {
      if (!csv_row.error.empty()) throw InputError(csv_path + ", row " + std::to_string(row.row), csv_row.error);
      row.trial = cell("trial");
      row.series = cell("series");
      row.note = cell("note");
      row.excluded = Trim(cell(MeasurementExclusionColumn()));
      if (row.trial.empty())
        throw InputError(CellContext(table, row.row, table.header[column.at("trial")]), "is empty");
      if (!trials.insert(row.trial).second)
        throw InputError(CellContext(table, row.row, table.header[column.at("trial")]),
                         "duplicate trial label '" + row.trial + "'");
      ReadVideoCells(e, table, row.row, cell("video"), cell("scene"), &row);
      FieldSource source;
      source.lookup = [&](const std::string& name) -> std::optional<FieldSource::Field> {
        if (name == "body") return FieldSource::Field{Text(body.at("type"), json_path + ": body.type"), ""};
        if (name == "L_convention")
          return apparatus.contains(name)
                     ? std::optional<FieldSource::Field>({Text(apparatus.at(name), json_path), ""})
                     : std::nullopt;
        if (auto it = column.find(name); it != column.end()) {
          const std::string& text = csv_row.cells[it->second];
          if (text.find_first_not_of(" \t") == std::string::npos) {
            if (name.rfind("u_", 0) != 0) return FieldSource::Field{"", ""};  // refused as empty
          } else {
            return FieldSource::Field{text, SplitUnitSuffix(table.header[it->second]).second};
          }
        }
        if (body.contains(name)) return FieldSource::Field{Text(body.at(name), json_path + ": body." + name), ""};
        if (apparatus.contains(name))
          return FieldSource::Field{Text(apparatus.at(name), json_path + ": apparatus." + name), ""};
        if (name.rfind("u_", 0) == 0 && defaults.contains(name.substr(2)))
          return FieldSource::Field{Text(defaults.at(name.substr(2)), json_path + ": uncertainties"), "", true};
        return std::nullopt;
      };
      source.context = [&](const std::string& name) -> std::string {
        if (auto it = column.find(name); it != column.end()) return CellContext(table, row.row, table.header[it->second]);
        if (name == "body") return json_path + ": body.type";
        if (body.contains(name)) return json_path + ": body." + name;
        if (apparatus.contains(name)) return json_path + ": apparatus." + name;
        if (name.rfind("u_", 0) == 0) return json_path + ": uncertainties." + name.substr(2);
        return csv_path + ", row " + std::to_string(row.row) + ": " + name +
               " (neither a column nor a constant in experiment.json)";
      };
      row.configuration = ParseConfiguration(source);
      const auto y = source.lookup("Y");
      if (!row.video.empty() && (!y || y->text.find_first_not_of(" \t") == std::string::npos)) {
        row.y_typed = false;  // from the video's rest position (app/video_trials.hpp)
        e.rows.push_back(std::move(row));
        continue;
      }
      row.Y.value = ParseQuantity(y ? y->text : "", Dimension::kLength, source.context("Y"),
                                  y ? y->default_unit : "");
      if (!(row.Y.value > 0.0)) throw InputError(source.context("Y"), "must be > 0 (a position beyond O)");
      try {
        RequireModelLength("Y", row.Y.value);
      } catch (const InputError& e) {
        throw InputError(source.context("Y"), e.rule());
      }
      if (const auto uy = source.lookup("u_Y")) {
        row.Y.u = ParseQuantity(uy->text, Dimension::kLength, source.context("u_Y"), uy->default_unit);
        if (row.Y.u < 0.0) throw InputError(source.context("u_Y"), "must be >= 0");
        try {
          RequireModelLength("u_Y", row.Y.u);
        } catch (const InputError& e) {
          throw InputError(source.context("u_Y"), e.rule());
        }
      }
    } catch (const InputError& err) {
      row.error = err.what();
      if (const auto it = column_of_context.find(err.quantity()); it != column_of_context.end())
        row.error_column = it->second;
      row.configuration.reset();
    }
    e.rows.push_back(std::move(row));
  }
  return e;
}

}  // namespace uphill
