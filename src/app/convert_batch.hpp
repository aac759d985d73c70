// ConvertBatch: `uphill convert --batch`: every row of a CSV file (or stdin, or a stream) one
// configuration (docs/convert.md, "Batch CSV"), the command's flags supplying defaults for
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
//
// BatchDetail::kSummary (what the table and the CSV print) lets rows that differ from an earlier
// one only in their numbers skip the Scene: they are gathered in blocks of kSummaryBlock rows and
// evaluated with the batch kernels of model/batch_convert.hpp in their kScalar form, which are the
// model's own expressions, so every number is bit for bit the one the full path gives (for a
// sphere or spheroid on line rails, or a sphere on rods, without uncertainties, --mu or --at-x;
// any other row, and any row outside the model's domain, takes the full path, in input order).
#pragma once

#include <cstddef>
#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "io/configuration.hpp"
#include "app/conversion.hpp"

namespace uphill {

// What each converted row carries: the whole result (JSON, verdicts, points), or only the values
// of ConversionSummary.
enum class BatchDetail { kFull, kSummary };

inline constexpr std::size_t kSummaryBlock = 4096;

// One input row's outcome: a result (kFull) or its summary (kSummary), or the one-line error it got.
struct ConvertedRow {
  int row = 0;  // spreadsheet row (header = 1); 0 for a configuration from flags
  std::optional<ConversionResult> result;
  std::optional<ConversionSummary> summary;
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
                  const std::function<void(const ConvertedRow&)>& on_row,
                  BatchDetail detail = BatchDetail::kFull);
void ConvertBatch(std::istream& in, const std::string& source, const FieldSource& defaults,
                  const ConversionOptions& options, const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row,
                  BatchDetail detail = BatchDetail::kFull);

}  // namespace uphill
