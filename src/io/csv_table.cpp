#include "io/csv_table.hpp"

#include <csv.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <set>

#include "model/input_error.hpp"

namespace uphill::io {
namespace {

struct ParseState {
  std::vector<std::string> record;
  std::vector<std::vector<std::string>> records;
};

void OnField(void* data, size_t size, void* state) {
  static_cast<ParseState*>(state)->record.emplace_back(static_cast<const char*>(data), size);
}

void OnRecordEnd(int /*terminator*/, void* state) {
  auto* s = static_cast<ParseState*>(state);
  s->records.push_back(std::move(s->record));
  s->record.clear();
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

}  // namespace

int CsvTable::Column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

CsvTable ReadCsv(std::istream& in, const std::string& source) {
  csv_parser parser;
  if (csv_init(&parser, CSV_STRICT | CSV_STRICT_FINI) != 0)
    throw std::runtime_error("libcsv: cannot initialise the parser");
  std::unique_ptr<csv_parser, void (*)(csv_parser*)> guard(&parser, csv_free);
  ParseState state;
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof buffer);
    const size_t n = static_cast<size_t>(in.gcount());
    if (n == 0) break;
    if (csv_parse(&parser, buffer, n, OnField, OnRecordEnd, &state) != n)
      throw InputError(source, std::string("malformed CSV after row ") +
                                   std::to_string(state.records.size()) + ": " +
                                   csv_strerror(csv_error(&parser)));
  }
  if (csv_fini(&parser, OnField, OnRecordEnd, &state) != 0)
    throw InputError(source, std::string("malformed CSV at the end: ") +
                                 csv_strerror(csv_error(&parser)));
  if (state.records.empty()) throw InputError(source, "is empty (expected a header row)");

  CsvTable table;
  table.source = source;
  std::set<std::string> seen;
  for (const std::string& name : state.records.front()) {
    std::string trimmed = Trim(name);
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first name.
    if (table.header.empty() && trimmed.rfind("\xEF\xBB\xBF", 0) == 0) trimmed = trimmed.substr(3);
    if (trimmed.empty())
      throw InputError(source, "row 1 (header), column " + std::to_string(table.header.size() + 1) +
                                   ": empty column name");
    if (!seen.insert(trimmed).second)
      throw InputError(source, "row 1 (header): duplicate column '" + trimmed + "'");
    table.header.push_back(trimmed);
  }
  for (size_t r = 1; r < state.records.size(); ++r) {
    CsvRow row;
    row.row = static_cast<int>(r) + 1;
    row.cells = std::move(state.records[r]);
    if (row.cells.size() != table.header.size())
      row.error = "has " + std::to_string(row.cells.size()) + " fields, the header has " +
                  std::to_string(table.header.size());
    table.rows.push_back(std::move(row));
  }
  return table;
}

CsvTable ReadCsvFile(const std::string& path) {
  if (path == "-") return ReadCsv(std::cin, "<stdin>");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be opened for reading");
  return ReadCsv(in, path);
}

std::string CellContext(const CsvTable& table, int row, const std::string& column) {
  return table.source + ", row " + std::to_string(row) + ", column " + column;
}

}  // namespace uphill::io
