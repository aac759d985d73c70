// `uphill convert`: apparatus measurements (L, H, D) or angles → θ, α, φ, X, x_max, the rest
// band, points on the path, uncertainties, and a plain-language verdict. One configuration from
// flags, or a CSV batch (file or stdin) in which each row is one configuration and the flags
// supply defaults for absent columns.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "app/convert_batch.hpp"
#include "flag_checks.hpp"
#include "app/conversion_printer.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "scene_flags.hpp"

namespace uphill::cli {
namespace {

struct ConvertFlags {
  SceneFlags scene;
  std::string batch;
  std::string at_x;
  std::string mu;
  bool csv = false;
  bool json = false;
  std::string length_unit = "mm";
  std::int64_t mc_trials = kConvertMonteCarloTrials;  // signed: "-1" is refused as -1, not wrapped
  std::uint64_t seed = kConvertSeed;
  const CLI::App* command = nullptr;  // to ask which flags were given
};

ConversionOptions Options(const ConvertFlags& f) {
  const CLI::App* c = f.command;
  if (f.json && f.csv) throw InputError("--csv/--json", "give at most one of them");
  RefuseIgnored(c, "--length-unit", f.json, "applies to the table and CSV only (JSON is in SI units)");
  RefuseEmpty(c, "--at-x", f.at_x, "positions with unit, e.g. 10mm,20mm");
  RefuseEmpty(c, "--mu", f.mu, "a rolling-resistance coefficient, e.g. 0.01");
  RefuseEmpty(c, "--batch", f.batch, "a CSV file, or - for stdin");
  ConversionOptions o;
  if (UnitFactor(Dimension::kLength, f.length_unit) == 0.0)
    throw InputError("--length-unit", "must be one of " + AcceptedUnits(Dimension::kLength));
  o.length_unit = f.length_unit;
  if (!f.at_x.empty()) o.at_x = ParseQuantityList(f.at_x, Dimension::kLength, "--at-x");
  if (!f.mu.empty()) {
    o.mu = ParseQuantity(f.mu, Dimension::kDimensionless, "--mu");
    RequireRollingResistance("--mu", *o.mu);
  }
  RequireMonteCarloTrials("--mc-trials", static_cast<double>(f.mc_trials));
  o.propagation.trials = static_cast<std::uint64_t>(f.mc_trials);
  o.propagation.seed = f.seed;
  return o;
}

// The optional columns of a batch's table and CSV, from its header and the flags (the values
// cannot be known before the rows are printed).
OptionalColumns BatchColumns(const BatchHeader& input, const ConvertFlags& f, const ConversionOptions& options) {
  OptionalColumns any;
  const FieldSource defaults = FlagSource(f.scene);
  const auto has = [&](const std::string& field) {
    for (const std::string& column : input.header)
      if (SplitUnitSuffix(column).first == field) return true;
    return defaults.lookup(field).has_value();
  };
  any.label = has("label");
  for (const std::string& name : ConfigurationFieldNames())
    if (name.rfind("u_", 0) == 0) any.uncertainty |= has(name);
  any.rest = options.mu.has_value();
  const auto body = defaults.lookup("body");
  any.cone = (body && body->text == "double-cone");
  for (const std::string& column : input.header) any.cone |= SplitUnitSuffix(column).first == "body";
  return any;
}

void Run(const ConvertFlags& f) {
  ConversionOptions options = Options(f);
  const OutputFormat format = f.json ? OutputFormat::kJson : f.csv ? OutputFormat::kCsv : OutputFormat::kTable;
  options.verdict = format == OutputFormat::kJson || f.batch.empty();  // only JSON and one setting's table show it
  if (f.batch.empty()) {
    ConvertedRow row;
    const Configuration configuration = ParseConfiguration(FlagSource(f.scene));
    const std::string why = "has no effect: no input has an uncertainty (give one as --u-<name>, e.g. --u-D 0.2mm)";
    RefuseIgnored(f.command, "--mc-trials", !configuration.HasUncertainty(), why);
    RefuseIgnored(f.command, "--seed", !configuration.HasUncertainty(), why);
    row.result = Convert(configuration, options);
    ConversionPrinter printer(std::cout, format, false, f.length_unit, ColumnsOf(*row.result));
    printer.Row(row);
    printer.Finish();
    return;
  }
  // Rows are printed as they are converted; a bad row is named on stderr as it is met.
  const FieldSource defaults = FlagSource(f.scene);
  std::unique_ptr<ConversionPrinter> printer;
  ConvertBatch(
      f.batch, defaults, options,
      [&](const BatchHeader& input) {
        printer = std::make_unique<ConversionPrinter>(std::cout, format, true, f.length_unit,
                                                      BatchColumns(input, f, options));
      },
      [&](const ConvertedRow& row) {
        printer->Row(row);
        if (row.error.empty()) return;
        std::cerr << "uphill: " << row.error << "\n";
        ExitStatus() = 2;
      },
      format == OutputFormat::kJson ? BatchDetail::kFull : BatchDetail::kSummary);
  printer->Finish();
}

}  // namespace

void AddConvertCommand(CLI::App& app) {
  auto flags = std::make_shared<ConvertFlags>();
  CLI::App* cmd = app.add_subcommand(
      "convert", "Apparatus measurements (L, H, D) or angles -> theta, alpha, X, x_max, rest band");
  AddSceneFlags(cmd, &flags->scene);
  cmd->add_option("--batch", flags->batch,
                  "CSV file (or - for stdin), one configuration per row; flags give defaults");
  cmd->add_option("--at-x", flags->at_x, "positions for the path, comma-separated, with unit");
  cmd->add_option("--mu", flags->mu, "rolling-resistance coefficient (rest band where |dz/dx| <= mu)");
  cmd->add_flag("--csv", flags->csv, "CSV output (units named in the header)");
  cmd->add_flag("--json", flags->json, "JSON output (SI units; keys in docs/convert.md)");
  cmd->add_option("--length-unit", flags->length_unit, "length unit of table and CSV: mm, cm, m, in")
      ->capture_default_str();
  cmd->add_option("--mc-trials", flags->mc_trials, "Monte Carlo trials for the uncertainties")
      ->capture_default_str();
  cmd->add_option("--seed", flags->seed, "Monte Carlo seed (same seed, same numbers)")->capture_default_str();
  flags->command = cmd;
  cmd->callback([flags] { Run(*flags); });
}

}  // namespace uphill::cli
