#include "io/xy_table.hpp"

#include <charconv>
#include <cmath>

#include "io/csv_table.hpp"
#include "model/input_error.hpp"

namespace uphill::io {
namespace {

double Cell(const CsvTable& table, const CsvRow& row, int column) {
  const std::string& text = row.cells[column];
  double v = 0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  while (begin < end && *begin == ' ') ++begin;
  if (begin < end && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, v);
  const std::string where = CellContext(table, row.row, table.header[column]);
  if (ec != std::errc() || ptr == begin) throw InputError(where, "'" + text + "' is not a number");
  for (const char* p = ptr; p < end; ++p)
    if (*p != ' ') throw InputError(where, "'" + text + "' is not a plain number");
  if (!std::isfinite(v)) throw InputError(where, "'" + text + "' is not a finite number");
  return v;
}

XyTable FromTable(const CsvTable& table) {
  for (const auto& name : table.header)
    if (name != "X" && name != "Y" && name != "uX" && name != "uY")
      throw InputError(CellContext(table, 1, name), "unknown column (expected X, Y and optionally uX, uY)");
  const int cx = table.Column("X"), cy = table.Column("Y"), cux = table.Column("uX"), cuy = table.Column("uY");
  if (cx < 0 || cy < 0) throw InputError(table.source + ", row 1", "the header must have columns X and Y");
  XyTable data;
  data.source = table.source;
  for (const CsvRow& row : table.rows) {
    try {
      if (!row.error.empty()) throw InputError(table.source + ", row " + std::to_string(row.row), row.error);
      const double x = Cell(table, row, cx), y = Cell(table, row, cy);
      const double ux = cux >= 0 ? Cell(table, row, cux) : 0.0, uy = cuy >= 0 ? Cell(table, row, cuy) : 0.0;
      data.x.push_back(x);
      data.y.push_back(y);
      if (cux >= 0) data.u_x.push_back(ux);
      if (cuy >= 0) data.u_y.push_back(uy);
      data.rows.push_back(row.row);
    } catch (const InputError& e) {
      data.row_errors.push_back(e.what());
    }
  }
  return data;
}

}  // namespace

XyTable ReadXy(std::istream& in, const std::string& source) { return FromTable(ReadCsv(in, source)); }

XyTable ReadXyFile(const std::string& path) { return FromTable(ReadCsvFile(path)); }

std::string XyTable::Locate(const std::string& quantity) const {
  // The fit layer names a value "X[i]", "Y[i]", "u(X)[i]" or "u(Y)[i]" (i counts read rows).
  const auto open = quantity.find('[');
  if (open == std::string::npos || quantity.back() != ']') return quantity;
  const std::string name = quantity.substr(0, open);
  const std::string column = name == "u(X)" ? "uX" : name == "u(Y)" ? "uY" : name;
  std::size_t i = 0;
  try {
    i = std::stoul(quantity.substr(open + 1));
  } catch (const std::exception&) {
    return quantity;
  }
  if (i >= rows.size()) return quantity;
  return source + ", row " + std::to_string(rows[i]) + ", column " + column;
}

}  // namespace uphill::io
