// XyTable: the input of `uphill fit --xy`, a CSV with the header X,Y and optionally uX,uY (plain
// numbers, all in the same unit, no unit suffix), read into vectors for the fits.
//
// A row that cannot be read (wrong field count, an empty, non-numeric or non-finite cell) is left
// out and its message kept in `row_errors` ("file, row 3, column Y: 'abc' is not a number"); the
// other rows are read. Problems with the file or its header throw InputError.
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace uphill::io {

struct XyTable {
  std::vector<double> x, y;
  std::vector<double> u_x, u_y;         // one per read row when the column exists, else empty
  std::vector<std::string> row_errors;  // rows left out, one line each
};

// Throws InputError naming the file for malformed CSV, an unknown column (anything but X, Y, uX,
// uY) or a missing X or Y column.
XyTable ReadXy(std::istream& in, const std::string& source);
// Opens `path` ("-" reads stdin); throws InputError naming the file when it cannot be read.
XyTable ReadXyFile(const std::string& path);

}  // namespace uphill::io
