// Fuzz target: io::ReadCsv followed by what `uphill convert --batch` does with the table
// (tools/uphill/convert_command.cpp, ConvertBatch and RowSource, mirrored here without command-line
// defaults): the column check, io::ParseConfiguration per row, io::Convert (first-order
// uncertainties only: Monte Carlo trials = 0), a point on the path, and the JSON output.
// Only uphill::InputError may escape a step; anything else (a crash, a sanitizer report, another
// exception) is a bug.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>

#include "io/configuration.hpp"
#include "io/conversion.hpp"
#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"

namespace {

using namespace uphill;

// RowSource of convert_command.cpp: a row's non-blank cells, with the unit of the header suffix.
io::FieldSource RowSource(const io::CsvTable& table, const io::CsvRow& row,
                          const std::map<std::string, int>& field_column) {
  io::FieldSource source;
  source.lookup = [&](const std::string& name) -> std::optional<io::FieldSource::Field> {
    if (auto it = field_column.find(name); it != field_column.end()) {
      const std::string& cell = row.cells[it->second];
      if (cell.find_first_not_of(" \t") != std::string::npos)
        return io::FieldSource::Field{cell, io::SplitUnitSuffix(table.header[it->second]).second};
    }
    return std::nullopt;
  };
  source.context = [&](const std::string& name) {
    if (auto it = field_column.find(name); it != field_column.end())
      return io::CellContext(table, row.row, table.header[it->second]);
    return table.source + ", row " + std::to_string(row.row) + ": --" + name;
  };
  return source;
}

void ConvertRow(const io::CsvTable& table, const io::CsvRow& row,
                const std::map<std::string, int>& field_column) {
  if (!row.error.empty()) return;
  const io::Configuration c = io::ParseConfiguration(RowSource(table, row, field_column));
  io::ConversionOptions options;
  options.mu = 0.01;
  options.propagation.trials = 0;  // first order only: Monte Carlo is the model's, not the reader's
  const io::ConversionResult r = io::Convert(c, options);
  (void)io::ToJson(r).dump();
  // A point halfway along the path, as --at-x would ask for.
  options.mu.reset();
  options.at_x = {0.5 * (r.scene.x_low() + r.scene.x_max())};
  (void)io::ToJson(io::Convert(c, options)).dump();
}

void Run(const std::string& text) {
  std::istringstream in(text);
  const io::CsvTable table = io::ReadCsv(in, "fuzz.csv");
  const auto& known = io::ConfigurationFieldNames();
  std::map<std::string, int> field_column;
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string base = io::SplitUnitSuffix(table.header[i]).first;
    if (base == "note") continue;
    if (std::find(known.begin(), known.end(), base) == known.end())
      throw InputError(table.source + ", row 1, column " + table.header[i], "unknown column");
    if (!field_column.emplace(base, static_cast<int>(i)).second)
      throw InputError(table.source + ", row 1, column " + table.header[i], "second time");
  }
  size_t converted = 0;
  for (const io::CsvRow& row : table.rows) {
    if (++converted > 32) break;  // enough rows to mix good and bad ones; keeps runs fast
    try {
      ConvertRow(table, row, field_column);
    } catch (const InputError&) {
      // A bad row: reported by convert, the other rows go on.
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    Run(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const InputError&) {
    // The documented refusal of a whole file.
  }
  return 0;
}
