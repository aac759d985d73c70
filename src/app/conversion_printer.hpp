// ConversionPrinter: the output formats of `uphill convert` (docs/convert.md): a readable table
// (lab units, each column naming its unit), CSV (the same columns) or JSON (SI, ToJson). Failed
// rows of a batch appear in every format, with their error, so the output lines up with the input
// rows.
//
// Rows are printed as they come (a batch of any size is never held): JSON as the elements of one
// array (from each row's ConversionResult), CSV line by line (from each row's ConversionSummary,
// numbers written with model/decimal_text.hpp straight into the output buffer); the table holds
// its first kTableSample rows to size its columns, then prints the rest with those widths (a
// wider cell shifts its line; an error after the sample, when the sample had none, goes at the
// end of its line). The optional columns - label, the uncertainties, the rest band, θ0 - are
// chosen before the first row: for a batch from its header and the flags, for one configuration
// from its result.
#pragma once

#include <cstddef>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "app/convert_batch.hpp"

namespace uphill {

enum class OutputFormat { kTable, kCsv, kJson };

// The optional columns of the table and the CSV.
struct OptionalColumns {
  bool label = false, uncertainty = false, rest = false, cone = false;
};
// For one configuration: the columns its result has.
OptionalColumns ColumnsOf(const ConversionResult& result);

inline constexpr std::size_t kTableSample = 10000;

class ConversionPrinter {
 public:
  ConversionPrinter(std::ostream& out, OutputFormat format, bool batch, std::string length_unit,
                    OptionalColumns columns);
  ~ConversionPrinter();
  void Row(const ConvertedRow& row);
  void Finish();  // closes the JSON array, prints a table held so far

 private:
  enum class Cell { kLabel, kBody, kTheta, kAlpha, kPhi, kX, kUX, kUXMc, kXMax, kRestLow, kRest, kTheta0, kRollsUp, kNote };
  struct Column {
    std::string header;
    Cell cell;
  };
  // Writes the text of one cell of a row at p (CSV quoting where the text may need it), which has
  // room for CellRoom(v) characters, and returns its end.
  char* WriteCell(char* p, Cell cell, const ConversionSummary& v, bool csv) const;
  std::size_t CellRoom(const ConversionSummary& v) const;
  void FlushCsv();
  std::vector<std::string> Cells(const ConvertedRow& row) const;
  void FlushTable();
  void TableLine(const std::vector<std::string>& cells, bool header = false);

  std::ostream& out_;
  OutputFormat format_;
  bool batch_;
  std::string unit_;
  double unit_factor_ = 1.0;  // metres per unit_
  std::vector<Column> columns_;
  std::size_t rows_ = 0;
  // The table's sample, its widths once known, and whether it shows the error column.
  std::vector<std::vector<std::string>> held_;
  std::vector<std::size_t> width_;
  bool error_column_ = false, table_started_ = false, finished_ = false;
  std::string body_names_[3];  // by BodyKind
  // CSV lines not yet written (csv_used_ bytes of csv_, written in blocks of kCsvBlock bytes).
  std::vector<char> csv_;
  std::size_t csv_used_ = 0;
  static constexpr std::size_t kCsvBlock = std::size_t{1} << 16;
};

}  // namespace uphill
