// Units (io/units.hpp), one setting converted as `uphill convert` does (io/conversion.hpp),
// experiment folders and their analysis as `uphill fit EXP` makes it, videos tracked
// (app/experiment_folder_analysis.hpp), X-Y tables (io/xy_table.hpp).
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "app/conversion.hpp"
#include "app/convert_batch.hpp"
#include "app/experiment_folder_analysis.hpp"
#include "app/row_check.hpp"
#include "bindings.hpp"
#include "io/configuration.hpp"
#include "io/experiment.hpp"
#include "io/xy_table.hpp"
#include "model/number_text.hpp"
#include "report/analysis.hpp"
#include "report/fit_json.hpp"
#include "report/report_summary.hpp"

namespace uphill::python {
namespace {

Dimension ParseDimension(const std::string& name) {
  static const std::map<std::string, Dimension> kNames = {
      {"length", Dimension::kLength},       {"angle", Dimension::kAngle},
      {"time", Dimension::kTime},           {"velocity", Dimension::kVelocity},
      {"acceleration", Dimension::kAcceleration}, {"dimensionless", Dimension::kDimensionless}};
  const auto it = kNames.find(name);
  if (it == kNames.end())
    throw InputError("dimension", "must be length, angle, time, velocity, acceleration or dimensionless (got \"" +
                                      name + "\")");
  return it->second;
}

// A field of a setting given as a Python value: text as on the command line ("1165 mm"), or a
// number in SI (metres, radians), which the parser reads with the SI unit of its dimension.
FieldSource KeywordSource(const py::kwargs& fields) {
  auto values = std::make_shared<std::map<std::string, FieldSource::Field>>();
  for (const auto& [key, value] : fields) {
    const std::string name = key.cast<std::string>();
    FieldSource::Field field;
    if (py::isinstance<py::str>(value)) {
      field.text = value.cast<std::string>();
    } else if (py::isinstance<py::bool_>(value)) {
      if (name != "along_rail") throw ArgumentTypeError(name, "expected text or a number");
      if (value.cast<bool>()) (*values)["L_convention"] = {"along-rail", ""};
      continue;
    } else if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", Number(value, name));
      field.text = text;
      const std::string base = name.rfind("u_", 0) == 0 ? name.substr(2) : name;
      field.default_unit = base == "theta" || base == "alpha" ? "rad" : "m";
    } else {
      throw ArgumentTypeError(name, "expected text with a unit (\"45 mm\") or a number in SI units");
    }
    (*values)[name] = field;
  }
  const auto& known = ConfigurationFieldNames();
  for (const auto& [name, field] : *values)
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw InputError(name, "is not a field of a setting (fields: body, R, a, b, h, L, H, D, theta, alpha, "
                             "rod_diameter, u_<name>, L_convention or along_rail=True, label)");
  FieldSource source;
  source.lookup = [values](const std::string& name) -> std::optional<FieldSource::Field> {
    const auto it = values->find(name);
    if (it == values->end()) return std::nullopt;
    return it->second;
  };
  source.context = [](const std::string& name) { return name; };
  return source;
}

py::dict UncertainToPython(const Uncertain& u) {
  py::dict d;
  d["value"] = u.value;
  d["u"] = u.u;
  return d;
}

py::dict ConfigurationToPython(const Configuration& c) {
  py::dict d;
  d["label"] = c.label;
  d["body"] = c.MakeBody().Name();
  d["across"] = UncertainToPython(c.across);
  d["along"] = UncertainToPython(c.along);
  if (c.from_apparatus) {
    d["L"] = UncertainToPython(c.L), d["H"] = UncertainToPython(c.H), d["D"] = UncertainToPython(c.D);
    d["L_convention"] = c.convention == LConvention::kAlongRail ? "along-rail" : "horizontal";
  } else {
    d["theta"] = UncertainToPython(c.theta), d["alpha"] = UncertainToPython(c.alpha);
  }
  d["rod_radius"] = UncertainToPython(c.rod_radius);
  return d;
}

// An experiment folder, read once; an analysis refers into the experiment it was made of (with
// the videos' rest positions as Y), which it keeps alive.
struct LoadedExperiment {
  std::shared_ptr<Experiment> experiment;
};

struct Analysis {
  std::shared_ptr<LoadedExperiment> loaded;
  ExperimentAnalysis analysis;
  std::vector<std::string> trial_errors;
  std::vector<std::string> cache_notes;
};

// An uphill.Experiment as it is, or a folder path read now.
std::shared_ptr<LoadedExperiment> ExperimentOf(const py::object& experiment) {
  if (py::isinstance<LoadedExperiment>(experiment)) return experiment.cast<std::shared_ptr<LoadedExperiment>>();
  auto loaded = std::make_shared<LoadedExperiment>();
  loaded->experiment = std::make_shared<Experiment>(LoadExperiment(py::str(experiment).cast<std::string>()));
  return loaded;
}

template <typename F>
py::array_t<double> RowArray(const ExperimentAnalysis& a, F&& value) {
  py::array_t<double> out(static_cast<py::ssize_t>(a.rows.size()));
  double* p = MutableData(out);
  for (std::size_t i = 0; i < a.rows.size(); ++i) p[i] = value(a.rows[i]);
  return out;
}

// The options `uphill convert` takes besides the setting: mu, --at-x, --mc-trials, --seed, in the
// command's ranges (model/input_ranges.hpp).
ConversionOptions ConversionOptionsOf(const py::object& mu, const py::object& at_x, const py::object& mc_trials,
                                      const py::object& seed) {
  ConversionOptions options;
  options.mu = OptionalQuantity(mu, Dimension::kDimensionless, "mu");
  if (options.mu) RequireRollingResistance("mu", *options.mu);
  if (!at_x.is_none())
    for (const auto& x : at_x) options.at_x.push_back(Quantity(x, Dimension::kLength, "at_x"));
  options.propagation.trials = Count(mc_trials, "mc_trials");
  RequireMonteCarloTrials("mc_trials", static_cast<double>(options.propagation.trials));
  options.propagation.seed = Count(seed, "seed");
  return options;
}

}  // namespace

void BindUnits(py::module_& m) {
  m.def(
      "parse_quantity",
      [](const std::string& text, const std::string& dimension, const std::string& name) {
        return ParseQuantity(text, ParseDimension(dimension), name);
      },
      py::arg("text"), py::arg("dimension") = "length", py::arg("name") = "value",
      R"(The SI value of a quantity written with its unit, as on the command line: "45 mm" -> 0.045 (m),
"10 deg" -> 0.1745... (rad), "50 ms" -> 0.05 (s), "9.81 m/s2". dimension: length, angle, time,
velocity, acceleration or dimensionless. A number without a unit is refused (InputError), as on the
command line: a guessed unit is a silent 25.4x error.)");
  m.def(
      "to_unit",
      [](const py::object& value, const std::string& dimension, const std::string& unit) {
        const Dimension d = ParseDimension(dimension);
        if (UnitFactor(d, unit) == 0.0) throw InputError("unit", "must be one of " + AcceptedUnits(d));
        const double converted = ToUnit(Number(value, "value"), d, unit);
        if (!std::isfinite(converted))  // 1e308 m in um
          throw InputError("value", "is too large to express in " + unit + " (got " + ExactText(Number(value, "value")) + ")");
        return converted;
      },
      py::arg("value"), py::arg("dimension"), py::arg("unit"),
      "A value in SI expressed in `unit` of `dimension` (e.g. to_unit(0.0254, \"length\", \"in\") == 1).");
  m.def("accepted_units", [](const std::string& dimension) { return AcceptedUnits(ParseDimension(dimension)); },
        py::arg("dimension"), "The unit names accepted for a dimension, e.g. \"mm, cm, m, km, um, in\".");
}

void BindFiles(py::module_& m) {
  m.def(
      "convert_setting",
      [](const py::object& mu, const py::object& at_x, const py::object& mc_trials, const py::object& seed,
         const std::string& length_unit, const py::kwargs& fields) {
        ConversionOptions options = ConversionOptionsOf(mu, at_x, mc_trials, seed);
        options.length_unit = length_unit;
        const Configuration configuration = ParseConfiguration(KeywordSource(fields));
        nlohmann::ordered_json json;
        {
          py::gil_scoped_release release;
          json = ToJson(Convert(configuration, options));
        }
        return ToPython(json);
      },
      py::kw_only(), py::arg("mu") = py::none(), py::arg("at_x") = py::none(),
      py::arg("mc_trials") = kConvertMonteCarloTrials, py::arg("seed") = kConvertSeed, py::arg("length_unit") = "mm",
      R"(One setting converted exactly as `uphill convert ... --json` does (app/conversion.hpp): returns
that JSON as a dict (SI units: m, rad; keys as documented for the command: theta, alpha, phi, x_eq,
z_eq, x_max, x_low, rolls_up, points, x_rest, x_rest_low, u_<key>, u_mc_<key>, verdict, ...).

Fields are the command's flags without "--" (underscores for dashes): body, R, a, b, h, L, H, D,
theta, alpha, rod_diameter, u_<name>, label, along_rail=True. Each value is text with its unit as
on the command line ("1165 mm", "10 deg") or a number in SI (m, rad). mu (rolling resistance),
at_x (positions, m or text), mc_trials (default 10^6, as the command) and seed (the command's
default) as for the command.)");

  m.def(
      "convert_batch_file",
      [](const std::string& path, const py::object& mu, const py::object& at_x, const py::object& mc_trials,
         const py::object& seed, const py::kwargs& defaults) {
        const ConversionOptions options = ConversionOptionsOf(mu, at_x, mc_trials, seed);
        const FieldSource source = KeywordSource(defaults);
        std::vector<nlohmann::ordered_json> rows;
        {
          py::gil_scoped_release release;
          ConvertBatch(path, source, options, [](const BatchHeader&) {}, [&rows](const ConvertedRow& row) {
            nlohmann::ordered_json j;
            j["row"] = row.row;
            if (row.result) {
              const nlohmann::ordered_json result = ToJson(*row.result);  // outlives the loop
              for (const auto& [key, value] : result.items()) j[key] = value;
            } else {
              j["error"] = row.error;
            }
            rows.push_back(std::move(j));
          });
        }
        py::list out;
        for (const auto& j : rows) out.append(ToPython(j));
        return out;
      },
      py::arg("path"), py::kw_only(), py::arg("mu") = py::none(), py::arg("at_x") = py::none(),
      py::arg("mc_trials") = kConvertMonteCarloTrials, py::arg("seed") = kConvertSeed,
      R"(A batch CSV converted as `uphill convert --batch PATH --json` does (app/convert_batch.hpp): one
configuration per row (format: docs/convert.md), keyword arguments as convert_setting's fields give
the defaults for absent columns and empty cells. Returns a list with a dict per row: "row" (the
spreadsheet row, header = 1) and the conversion's keys (SI), or "error" (file, row, column, rule)
for a row that could not be converted; the other rows are converted as usual. InputError for the
file as a whole (unreadable, an unknown column, no rows).)");

  py::class_<LoadedExperiment, std::shared_ptr<LoadedExperiment>>(m, "Experiment",
                                                                  R"(An experiment folder (format uphill-experiment/1, data/README.md), read once.

Rows that cannot be used keep their error (file, row, column, rule); the others are loaded.)")
      .def_property_readonly("directory", [](const LoadedExperiment& e) { return e.experiment->directory; })
      .def_property_readonly("title", [](const LoadedExperiment& e) { return e.experiment->title; })
      .def_property_readonly("operator", [](const LoadedExperiment& e) { return e.experiment->operator_name; })
      .def_property_readonly("date", [](const LoadedExperiment& e) { return e.experiment->date; })
      .def_property_readonly("notes", [](const LoadedExperiment& e) { return e.experiment->notes; })
      .def_property_readonly("metadata", [](const LoadedExperiment& e) { return ToPython(e.experiment->metadata); },
                             "experiment.json as read (a dict).")
      .def_property_readonly(
          "rows",
          [](const LoadedExperiment& e) {
            py::list rows;
            for (const ExperimentRow& r : e.experiment->rows) {
              py::dict d;
              d["row"] = r.row, d["trial"] = r.trial, d["series"] = r.series, d["note"] = r.note;
              d["Y"] = r.Y.value, d["u_Y"] = r.Y.u;
              d["configuration"] = r.configuration ? py::object(ConfigurationToPython(*r.configuration)) : py::none();
              d["error"] = r.error.empty() ? py::object(py::none()) : py::object(py::str(r.error));
              d["excluded"] = r.excluded.empty() ? py::object(py::none()) : py::object(py::str(r.excluded));
              rows.append(d);
            }
            return rows;
          },
          "One dict per row of measurements.csv: row (spreadsheet row, header = 1), trial, series, note, Y and u_Y "
          "(m), configuration (values and standard uncertainties in SI) or error (file, row, column, rule), excluded "
          "(why the row is left out of the fits, or None).")
      .def_property_readonly(
          "scenes",
          [](const LoadedExperiment& e) {
            std::vector<Scene> scenes;
            for (const ExperimentRow* r : e.experiment->UsableRows()) scenes.push_back(r->configuration->MakeScene());
            return scenes;
          },
          "An uphill.Scene per usable row, in file order.")
      .def_property_readonly("errors", [](const LoadedExperiment& e) { return e.experiment->Errors(); },
                             "The rows left out, one line each.");

  m.def(
      "read_experiment",
      [](const std::string& directory) {
        auto loaded = std::make_shared<LoadedExperiment>();
        loaded->experiment = std::make_shared<Experiment>(LoadExperiment(directory));
        return loaded;
      },
      py::arg("directory"),
      "Reads an experiment folder (experiment.json + measurements.csv). InputError names the file, key or "
      "column for a folder that cannot be analysed at all.");

  py::class_<Analysis>(m, "Analysis", R"(The analysis of an experiment, as `uphill fit EXP` prints it (report/analysis.hpp).

Per fitted row (NumPy arrays, file order; rows excluded from the fit are in `excluded`): theta, alpha (rad), x_eq (X) with u_x_eq (first order)
and u_x_eq_mc (Monte Carlo), x_max, y and u_y (m); flags: per row a list of dicts (code, field,
message, severity), the row check's (uphill.check_row) and the Monte Carlo's u_disagrees. fits: dict method -> FitReport ("ols", "wls",
"york", "robust", "friction"), unavailable: dict method -> reason. friction_vs_line: dict
(delta_chi2, delta_aic, delta_bic, akaike_weight_friction, verdict). to_json(): `uphill fit EXP --json`.)")
      .def_property_readonly("experiment", [](const Analysis& a) { return a.loaded; })
      .def_property_readonly("theta", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.theta; }); })
      .def_property_readonly("alpha", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.alpha; }); })
      .def_property_readonly("x_eq", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.x_eq; }); })
      .def_property_readonly("u_x_eq", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.u_x_eq; }); })
      .def_property_readonly("u_x_eq_mc",
                             [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.u_x_eq_mc; }); })
      .def_property_readonly("x_max", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.x_max; }); })
      .def_property_readonly("y", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.y; }); })
      .def_property_readonly("u_y", [](const Analysis& a) { return RowArray(a.analysis, [](const AnalysedRow& r) { return r.u_y; }); })
      .def_property_readonly("trials",
                             [](const Analysis& a) {
                               std::vector<std::string> t;
                               for (const auto& r : a.analysis.rows) t.push_back(r.source->trial);
                               return t;
                             })
      .def_property_readonly("flags",
                             [](const Analysis& a) {
                               py::list f;
                               for (const auto& r : a.analysis.rows) f.append(ToPython(FlagsJson(r.flags)));
                               return f;
                             })
      .def_property_readonly("fits",
                             [](const Analysis& a) {
                               py::dict d;
                               for (const auto& f : a.analysis.fits)
                                 if (f.report) d[py::str(f.method)] = *f.report;
                               return d;
                             })
      .def_property_readonly("unavailable",
                             [](const Analysis& a) {
                               py::dict d;
                               for (const auto& f : a.analysis.fits)
                                 if (!f.report) d[py::str(f.method)] = f.unavailable;
                               return d;
                             })
      .def_property_readonly("friction_vs_line",
                             [](const Analysis& a) -> py::object {
                               if (!a.analysis.friction_vs_line) return py::none();
                               const ModelComparison& c = *a.analysis.friction_vs_line;
                               py::dict d;
                               d["delta_chi2"] = c.delta_chi2, d["delta_aic"] = c.delta_aic, d["delta_bic"] = c.delta_bic;
                               d["akaike_weight_friction"] = c.akaike_weight_second;
                               d["verdict"] = c.verdict;
                               return d;
                             })
      .def_property_readonly("excluded",
                             [](const Analysis& a) {
                               py::list out;
                               for (const AnalysedRow& r : a.analysis.excluded_rows) {
                                 py::dict d;
                                 d["trial"] = r.source->trial, d["row"] = r.source->row, d["reason"] = r.source->excluded;
                                 d["x_eq"] = r.x_eq, d["u_x_eq"] = r.u_x_eq, d["y"] = r.y, d["u_y"] = r.u_y;
                                 d["flags"] = ToPython(FlagsJson(r.flags));
                                 out.append(d);
                               }
                               return out;
                             },
                             "The rows excluded from the fits (measurements.csv's excluded column), one dict each: "
                             "trial, row, reason, x_eq, u_x_eq, y, u_y (m), flags. They are in no array above and "
                             "in no fit.")
      .def_property_readonly("summary",
                             [](const Analysis& a) {
                               const ReportSummary s = SummariseAnalysis(a.analysis);
                               py::dict d;
                               d["preferred"] = s.preferred, d["quote"] = s.quote, d["why"] = s.why;
                               d["flagged"] = s.flagged, d["excluded"] = s.excluded;
                               return d;
                             },
                             "The report's summary (report/report_summary.hpp): preferred model, the numbers to "
                             "quote, why, flagged rows still fitted, excluded rows.")
      .def_property_readonly("row_errors", [](const Analysis& a) { return a.analysis.row_errors; })
      .def_property_readonly("trial_errors", [](const Analysis& a) { return a.trial_errors; },
                             "The videos that could not be analysed, one line each (trial, file, why).")
      .def_property_readonly("notes", [](const Analysis& a) { return a.analysis.notes; })
      .def_property_readonly("cache_notes", [](const Analysis& a) { return a.cache_notes; },
                             "The damaged cache entries that were tracked again, one line each.")
      .def("to_json", [](const Analysis& a) { return ToPython(AnalysisToJson(a.analysis)); },
           "The analysis as `uphill fit EXP --json` prints it (fit.json's content, SI units).");

  m.def(
      "analyse_experiment",
      [](const py::object& experiment, const py::object& mc_trials, const py::object& seed,
         const py::object& outlier_threshold, unsigned jobs) {
        ExperimentFolderOptions options;
        options.analysis.mc_trials = Count(mc_trials, "mc_trials");
        RequireMonteCarloTrials("mc_trials", static_cast<double>(options.analysis.mc_trials));
        options.analysis.seed = Count(seed, "seed");
        options.analysis.outlier_threshold = Number(outlier_threshold, "outlier_threshold");
        options.jobs = jobs;
        const bool loaded = py::isinstance<LoadedExperiment>(experiment);
        const std::shared_ptr<Experiment> given =
            loaded ? experiment.cast<std::shared_ptr<LoadedExperiment>>()->experiment : nullptr;
        const std::string directory = loaded ? "" : py::str(experiment).cast<std::string>();
        ExperimentFolderAnalysis folder;
        {
          py::gil_scoped_release release;
          // The given uphill.Experiment stays as read: the analysis fills Y from the videos in its own copy.
          folder = given ? AnalyseLoadedExperiment(*given, options) : AnalyseExperimentFolder(directory, options);
        }
        auto result = std::make_unique<Analysis>();
        result->loaded = std::make_shared<LoadedExperiment>(LoadedExperiment{folder.experiment});
        result->analysis = std::move(folder.analysis);
        result->trial_errors = std::move(folder.trial_errors);
        result->cache_notes = std::move(folder.notes);
        return result;
      },
      py::arg("experiment"), py::kw_only(), py::arg("mc_trials") = kAnalysisMonteCarloTrials,
      py::arg("seed") = kAnalysisSeed, py::arg("outlier_threshold") = kAnalysisOutlierThreshold, py::arg("jobs") = 0,
      R"(Analyses an experiment (a folder path or an uphill.Experiment) as `uphill fit EXP` does
(app/experiment_folder_analysis.hpp): the trials' videos, when the folder has any, are tracked
(jobs at a time, 0: one per core; cached in the folder) and a row with an empty Y takes its video's
rest position; then per row theta, alpha, X ± u(X) (first order and Monte Carlo with mc_trials per
row, the command's default) against Y ± u(Y), and the five fits of Y against X. Returns an
uphill.Analysis (trial_errors: the videos that could not be analysed). InputError when no row is
usable.)");

  m.def(
      "check_row",
      [](const py::object& experiment, const py::object& row, const std::string& unit) {
        const std::shared_ptr<LoadedExperiment> loaded = ExperimentOf(experiment);
        const std::vector<ExperimentRow>& rows = loaded->experiment->rows;
        const ExperimentRow* chosen = nullptr;
        if (py::isinstance<py::str>(row)) {
          const std::string trial = row.cast<std::string>();
          for (const ExperimentRow& r : rows)
            if (r.trial == trial && !chosen) chosen = &r;
          if (!chosen) throw InputError("row", "no row has the trial label '" + trial + "'");
        } else {
          const std::uint64_t index = Count(row, "row");
          if (index >= rows.size())
            throw InputError("row", "must be an index of the experiment's rows, 0 to " + std::to_string(rows.size() - 1) +
                                        " (got " + std::to_string(index) + ")");
          chosen = &rows[index];
        }
        return ToPython(RowCheckJson(CheckRow(*loaded->experiment, *chosen), unit));
      },
      py::arg("experiment"), py::arg("row"), py::kw_only(), py::arg("unit") = "m",
      R"(The row check the page, `uphill fit` and `uphill report` show (app/row_check.hpp): row is an index
into experiment.rows or a trial label of an experiment (a folder path or an uphill.Experiment). Returns
a dict: theta_deg, alpha_deg, x, u_x, x_max, crossbar, y, u_y, residual (lengths in `unit`, None when
unknown) and flags, a list of dicts code, field, message, severity.)");

  m.def(
      "read_xy",
      [](const std::string& path) {
        const XyTable t = ReadXyFile(path);
        py::dict d;
        auto array = [](const std::vector<double>& v) { return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data()); };
        d["x"] = array(t.x), d["y"] = array(t.y);
        d["u_x"] = t.u_x.empty() ? py::object(py::none()) : py::object(array(t.u_x));
        d["u_y"] = t.u_y.empty() ? py::object(py::none()) : py::object(array(t.u_y));
        std::vector<int> rows(t.x.size());
        for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = t.RowOf(i);
        d["rows"] = rows;
        d["left_out"] = t.left_out;
        d["row_errors"] = t.row_errors;
        return d;
      },
      py::arg("path"),
      R"(Reads the X-Y table of `uphill fit --xy` (header X,Y and optionally uX,uY; plain numbers in one
unit): dict of float64 arrays x, y, u_x, u_y (None when absent), the spreadsheet row of each (rows),
and the rows left out (left_out) with their reasons (row_errors).)");
}

}  // namespace uphill::python
