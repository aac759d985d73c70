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
  std::string source;                   // file name or "<stdin>"
  std::vector<int> rows;                // spreadsheet row of each read row
  std::vector<double> x, y;
  std::vector<double> u_x, u_y;         // one per read row when the column exists, else empty
  std::vector<std::string> row_errors;  // rows left out, one line each

  // "file, row 4, column uX" for the fit layer's name of a value, "u(X)[2]"; other names as given.
  std::string Locate(const std::string& quantity) const;
};

// Throws InputError naming the file for malformed CSV, an unknown column (anything but X, Y, uX,
// uY) or a missing X or Y column.
XyTable ReadXy(std::istream& in, const std::string& source);
// Opens `path` ("-" reads stdin); throws InputError naming the file when it cannot be read.
XyTable ReadXyFile(const std::string& path);

}  // namespace uphill::io
