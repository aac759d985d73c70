#include "io/csv_table.hpp"

#include <iostream>

#include "io/csv_records.hpp"
#include "model/input_error.hpp"

namespace uphill {

int CsvTable::Column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

CsvTable Collect(CsvRecords& records) {
  CsvTable table;
  table.source = records.source();
  table.header = records.header();
  CsvRecords::Record record;
  while (records.Next(&record)) {
    // Malformed quoting leaves the rest of the file in doubt: the whole table is refused.
    if (record.malformed) throw InputError(table.source, "row " + std::to_string(record.row) + ": " + record.error);
    CsvRow row;
    row.row = record.row;
    row.cells.assign(record.cells.begin(), record.cells.end());
    row.error = record.error;
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace

CsvTable ReadCsv(std::istream& in, const std::string& source) {
  CsvRecords records(in, source);
  return Collect(records);
}

CsvTable ReadCsvFile(const std::string& path) {
  CsvRecords records(path);
  return Collect(records);
}

std::string CellContext(const CsvTable& table, int row, const std::string& column) {
  return table.source + ", row " + std::to_string(row) + ", column " + column;
}

}  // namespace uphill
