// Fuzz target: ReadCsv followed by what `uphill convert --batch` does with the table
// (tools/uphill/convert_command.cpp, ConvertBatch, without command-line defaults): the column
// check of ConfigurationTable, ParseConfiguration per row, Convert (first-order
// uncertainties only: Monte Carlo trials = 0), a point on the path, and the JSON output.
// Only uphill::InputError may escape a step; anything else (a crash, a sanitizer report, another
// exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "io/configuration.hpp"
#include "io/configuration_table.hpp"
#include "io/conversion.hpp"
#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"

namespace {

using namespace uphill;

void ConvertRow(const ConfigurationTable& configurations, const CsvRow& row) {
  if (!row.error.empty()) return;
  const Configuration c = ParseConfiguration(configurations.RowSource(row));
  ConversionOptions options;
  options.mu = 0.01;
  options.propagation.trials = 0;  // first order only: Monte Carlo is the model's, not the reader's
  const ConversionResult r = Convert(c, options);
  (void)ToJson(r).dump();
  // A point halfway along the path, as --at-x would ask for.
  options.mu.reset();
  options.at_x = {0.5 * (r.scene.x_low() + r.scene.x_max())};
  (void)ToJson(Convert(c, options)).dump();
}

void Run(const std::string& text) {
  std::istringstream in(text);
  const CsvTable table = ReadCsv(in, "fuzz.csv");
  const ConfigurationTable configurations(table);
  size_t converted = 0;
  for (const CsvRow& row : table.rows) {
    if (++converted > 32) break;  // enough rows to mix good and bad ones; keeps runs fast
    try {
      ConvertRow(configurations, row);
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
