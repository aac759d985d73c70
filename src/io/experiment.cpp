#include "io/experiment.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/length_range.hpp"

namespace uphill {
namespace {

using nlohmann::json;

bool IsColumn(const std::string& name) {
  const auto& labels = MeasurementLabelColumns();
  const auto& quantities = MeasurementQuantities();
  return std::find(labels.begin(), labels.end(), name) != labels.end() ||
         std::find(quantities.begin(), quantities.end(), name) != quantities.end();
}

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

}  // namespace

std::vector<const ExperimentRow*> Experiment::UsableRows() const {
  std::vector<const ExperimentRow*> out;
  for (const auto& r : rows)
    if (r.error.empty()) out.push_back(&r);
  return out;
}

std::vector<std::string> Experiment::Errors() const {
  std::vector<std::string> out;
  for (const auto& r : rows)
    if (!r.error.empty()) out.push_back(r.error);
  return out;
}

Experiment LoadExperiment(const std::string& directory) {
  ExperimentFolder folder = ReadExperimentJson(directory);
  const std::string& json_path = folder.json_path;
  const std::string& csv_path = folder.csv_path;
  Experiment e;
  e.directory = directory;
  e.metadata = std::move(folder.metadata);
  const json& meta = e.metadata;
  CheckKeys(meta, ExperimentKeys(), json_path);
  if (!meta.contains("format") || meta.at("format") != kExperimentFormat)
    throw InputError(json_path + ": format",
                     std::string("must be \"") + kExperimentFormat + "\" (got " +
                         (meta.contains("format") ? Shown(meta.at("format")) : "nothing") + ")");
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

  // Required here (the page may create a folder before its first row; an analysis needs rows).
  const CsvTable table = ReadCsvFile(csv_path);
  std::map<std::string, int> column;  // quantity -> column index
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string base = SplitUnitSuffix(table.header[i]).first;
    const std::string where = CellContext(table, 1, table.header[i]);
    if (!IsColumn(base)) throw InputError(where, "unknown column (see data/README.md)");
    if (!column.emplace(base, static_cast<int>(i)).second)
      throw InputError(where, "gives '" + base + "' a second time");
    if (apparatus.contains(base))
      throw InputError(where, "'" + base + "' is also a constant in experiment.json (apparatus." + base +
                                  "): give it in one place only");
  }
  for (const char* required : {"trial", "Y"})
    if (!column.count(required))
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
    try {
      if (!csv_row.error.empty()) throw InputError(csv_path + ", row " + std::to_string(row.row), csv_row.error);
      row.trial = cell("trial");
      row.series = cell("series");
      row.note = cell("note");
      if (row.trial.empty())
        throw InputError(CellContext(table, row.row, table.header[column.at("trial")]), "is empty");
      if (!trials.insert(row.trial).second)
        throw InputError(CellContext(table, row.row, table.header[column.at("trial")]),
                         "duplicate trial label '" + row.trial + "'");
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
      row.configuration.reset();
    }
    e.rows.push_back(std::move(row));
  }
  return e;
}

}  // namespace uphill
