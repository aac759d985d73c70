#include "io/xy_table.hpp"

#include <fast_float/fast_float.h>
#include <sys/stat.h>

#include <cmath>

#include "io/csv_records.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

// Reserve the columns after this many rows, from the bytes they took.
constexpr std::size_t kSampleRows = 4096;

// A cell as a finite number ('+' allowed before it); empty string when it is one, else the rule.
const char* Parse(std::string_view text, double* value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin < end && *begin == '+') ++begin;
  const auto [ptr, ec] = fast_float::from_chars(begin, end, *value);
  if (ec != std::errc() || ptr == begin) return "is not a number";
  if (ptr != end) return "is not a plain number";
  if (!std::isfinite(*value)) return "is not a finite number";
  return nullptr;
}

XyTable Read(CsvRecords& records, const RowErrorSink& on_row_error, std::uint64_t file_bytes) {
  XyTable data;
  data.source = records.source();
  for (const auto& name : records.header())
    if (name != "X" && name != "Y" && name != "uX" && name != "uY")
      throw InputError(data.source + ", row 1, column " + name, "unknown column (expected X, Y and optionally uX, uY)");
  const int cx = records.Column("X"), cy = records.Column("Y"), cux = records.Column("uX"), cuy = records.Column("uY");
  if (cx < 0 || cy < 0) throw InputError(data.source + ", row 1", "the header must have columns X and Y");
  const int columns[4] = {cx, cy, cux, cuy};
  std::vector<double>* out[4] = {&data.x, &data.y, &data.u_x, &data.u_y};
  const auto left_out = [&](int row, const std::string& message) {
    data.left_out.push_back(row);
    if (on_row_error)
      on_row_error(message);
    else
      data.row_errors.push_back(message);
  };
  CsvRecords::Record record;
  std::size_t rows = 0;
  while (records.Next(&record)) {
    if (!record.error.empty()) {
      left_out(record.row, data.source + ", row " + std::to_string(record.row) + ": " + record.error);
      continue;
    }
    double v[4] = {0, 0, 0, 0};
    const char* rule = nullptr;
    int bad = -1;
    for (int k = 0; k < 4 && !rule; ++k)
      if (columns[k] >= 0 && (rule = Parse(record.cells[static_cast<std::size_t>(columns[k])], &v[k]))) bad = k;
    if (rule) {
      const std::string_view text = record.cells[static_cast<std::size_t>(columns[bad])];
      left_out(record.row, data.source + ", row " + std::to_string(record.row) + ", column " +
                               records.header()[static_cast<std::size_t>(columns[bad])] + ": '" + std::string(text) +
                               "' " + rule);
      continue;
    }
    for (int k = 0; k < 4; ++k)
      if (columns[k] >= 0) out[k]->push_back(v[k]);
    if (++rows == kSampleRows && file_bytes > records.consumed()) {
      // The rest of the file in rows like these, with 10 % to spare.
      const double per_row = static_cast<double>(records.consumed()) / static_cast<double>(rows);
      const auto expected = static_cast<std::size_t>(1.1 * static_cast<double>(file_bytes) / per_row) + kSampleRows;
      for (int k = 0; k < 4; ++k)
        if (columns[k] >= 0) out[k]->reserve(expected);
    }
  }
  return data;
}

std::uint64_t FileBytes(const std::string& path) {
  struct stat st {};
  if (path == "-" || stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return 0;
  return static_cast<std::uint64_t>(st.st_size);
}

// Every cell must parse as a number, so non-ASCII bytes fail there: no separate UTF-8 scan.
CsvRecords::Options Options() {
  CsvRecords::Options options;
  options.check_utf8 = false;
  return options;
}

}  // namespace

XyTable ReadXy(std::istream& in, const std::string& source, const RowErrorSink& on_row_error) {
  CsvRecords records(in, source, Options());
  return Read(records, on_row_error, 0);
}

XyTable ReadXyFile(const std::string& path, const RowErrorSink& on_row_error) {
  CsvRecords records(path, Options());
  return Read(records, on_row_error, FileBytes(path));
}

int XyTable::RowOf(std::size_t i) const {
  std::size_t row = i + 2;  // header = row 1
  for (int skipped : left_out) {
    if (static_cast<std::size_t>(skipped) > row) break;
    ++row;
  }
  return static_cast<int>(row);
}

std::string XyTable::Locate(const std::string& quantity) const {
  // The fit layer names a value "X[i]", "Y[i]", "u(X)[i]" or "u(Y)[i]" (i counts read rows).
  const auto open = quantity.find('[');
  // A rule about the data as a whole ("rows", "u(Y)", "X"): the file, then the quantity.
  if (open == std::string::npos || quantity.back() != ']') return source + ": " + quantity;
  const std::string name = quantity.substr(0, open);
  const std::string column = name == "u(X)" ? "uX" : name == "u(Y)" ? "uY" : name;
  std::size_t i = 0;
  try {
    i = std::stoul(quantity.substr(open + 1));
  } catch (const std::exception&) {
    return source + ": " + quantity;
  }
  return source + ", row " + std::to_string(RowOf(i)) + ", column " + column;
}

}  // namespace uphill
