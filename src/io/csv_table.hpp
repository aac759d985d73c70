// CsvTable: a CSV file read into memory as text cells (RFC 4180; read by CsvRecords,
// csv_records.hpp, which holds one record at a time - for large inputs use it directly), with
// the row numbers people see in a spreadsheet, so that every later error can name file, row and
// column.
//
// Conventions: the first record is the header; header names are trimmed, must be non-empty and
// unique. Blank lines are skipped. Row numbers are spreadsheet rows: the header is row 1, the
// first data record row 2 (a quoted field spanning lines counts as one row). A record with a
// different number of fields than the header, a cell that is not valid UTF-8, or a line longer
// than 1 MiB, is kept with `error` set, so that the other rows can still be processed.
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace uphill {

struct CsvRow {
  int row = 0;                      // spreadsheet row number (header = 1)
  std::vector<std::string> cells;   // one per header column when error is empty
  std::string error;                // non-empty: the record is malformed (field count, UTF-8)
};

struct CsvTable {
  std::string source;               // file name, or "<stdin>"
  std::vector<std::string> header;
  std::vector<CsvRow> rows;

  // Index of the column named `name`, or -1.
  int Column(const std::string& name) const;
};

// Throws InputError("<source>", rule) when the input cannot be read, is empty, has no header, a
// malformed quote (naming its row), or an empty, duplicate or not UTF-8 header name.
CsvTable ReadCsv(std::istream& in, const std::string& source);
// Opens `path` ("-" reads stdin); throws InputError naming the file when it cannot be read.
CsvTable ReadCsvFile(const std::string& path);

// "file, row 3, column L_mm: " — the prefix of every message about a cell.
std::string CellContext(const CsvTable& table, int row, const std::string& column);

}  // namespace uphill
