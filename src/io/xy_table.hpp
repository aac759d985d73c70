// XyTable: the input of `uphill fit --xy`, a CSV with the header X,Y and optionally uX,uY (plain
// numbers, all in the same unit, no unit suffix), read into columns for the fits.
//
// Read in bounded memory besides the columns themselves (CsvRecords, csv_records.hpp: 1 MiB
// blocks, no copy or allocation per row), the numbers converted by fast_float (exact, correctly
// rounded, as std::from_chars): 8 bytes per value and column, nothing else per row. From a file
// whose size is known the columns are reserved once from the size of the first rows (no
// reallocation and copy as they grow).
//
// A row that cannot be read (wrong field count, an empty, non-numeric or non-finite cell, a line
// longer than 1 MiB, malformed quoting) is left out: its one-line message ("file, row 3, column Y:
// 'abc' is not a number") goes to `on_row_error` at once, or into `row_errors` when no callback is
// given; the other rows are read. Problems with the file or its header throw InputError.
#pragma once

#include <cstddef>
#include <functional>
#include <istream>
#include <string>
#include <vector>

namespace uphill {

using RowErrorSink = std::function<void(const std::string& message)>;

struct XyTable {
  std::string source;                   // file name or "<stdin>"
  std::vector<double> x, y;
  std::vector<double> u_x, u_y;         // one per read row when the column exists, else empty
  std::vector<int> left_out;            // spreadsheet rows of the records left out, ascending
  std::vector<std::string> row_errors;  // their messages, when ReadXy had no on_row_error

  // Spreadsheet row of read row i (the header is row 1).
  int RowOf(std::size_t i) const;
  // "file, row 4, column uX" for the fit layer's name of a value, "u(X)[2]"; "file: rows" for a
  // rule about the data as a whole ("rows", "u(Y)").
  std::string Locate(const std::string& quantity) const;
};

// Throws InputError naming the file when it cannot be read, for malformed CSV in the header, an
// unknown column (anything but X, Y, uX, uY) or a missing X or Y column.
XyTable ReadXy(std::istream& in, const std::string& source, const RowErrorSink& on_row_error = {});
// Opens `path` ("-" reads stdin).
XyTable ReadXyFile(const std::string& path, const RowErrorSink& on_row_error = {});

}  // namespace uphill
