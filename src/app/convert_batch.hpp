// ConvertBatch: `uphill convert --batch`: every row of a CSV file (or stdin, or a stream) one
// configuration (README, "Batch CSV of convert"), the command's flags supplying defaults for
// absent columns and empty cells.
//
// The file is read record by record (CsvRecords, io/csv_records.hpp: bounded memory, no copy of
// the input) and each row is converted and handed on, in input order, before the next is read:
// memory does not grow with the number of rows, the caller writes each result as it comes. A row
// that cannot be read or converted comes with its one-line error (naming file, row, column and
// rule) instead of a result, and the rows after it are converted as usual.
//
// Cost per row: parsing the configuration from the cells, the closed forms of the model (Scene),
// and, only when the configuration has uncertainties, the propagation (Monte Carlo with
// ConversionOptions::propagation's trials per row).
#pragma once

#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "app/conversion.hpp"

namespace uphill {

// One input row's outcome: a result, or the one-line error it got.
struct ConvertedRow {
  int row = 0;  // spreadsheet row (header = 1); 0 for a configuration from flags
  std::optional<ConversionResult> result;
  std::string error;
};

struct BatchHeader {
  std::string source;               // the file's name, or "<stdin>"
  std::vector<std::string> header;  // its columns
};

// Throws InputError for the input as a whole (cannot be read, empty, an unknown column, a
// header-only file). on_header runs once, after the header is checked and before the first row.
void ConvertBatch(const std::string& path, const FieldSource& defaults, const ConversionOptions& options,
                  const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row);
void ConvertBatch(std::istream& in, const std::string& source, const FieldSource& defaults,
                  const ConversionOptions& options, const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row);

}  // namespace uphill
