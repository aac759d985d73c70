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

// Index of the first byte that is not part of well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF), or npos.
size_t InvalidUtf8At(const std::string& s) {
  size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    size_t more = 0;                     // continuation bytes
    unsigned char low = 0x80, high = 0xBF;  // range of the first continuation byte
    if (c >= 0xC2 && c <= 0xDF) {
      more = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      more = 2;
      if (c == 0xE0) low = 0xA0;   // overlong
      if (c == 0xED) high = 0x9F;  // surrogates
    } else if (c >= 0xF0 && c <= 0xF4) {
      more = 3;
      if (c == 0xF0) low = 0x90;   // overlong
      if (c == 0xF4) high = 0x8F;  // above U+10FFFF
    } else {
      return i;
    }
    if (s.size() - i <= more) return i;
    for (size_t k = 1; k <= more; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (k == 1 ? (b < low || b > high) : (b < 0x80 || b > 0xBF)) return i;
    }
    i += more + 1;
  }
  return std::string::npos;
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
  // CSV files are UTF-8 (data/README.md). Text in another encoding (a Latin-1 spreadsheet
  // export) is refused here, with its row and column: its bytes would otherwise reach the JSON
  // outputs, where nlohmann::json throws type_error 316 (found by fuzzing: uphill convert --json
  // ended as an internal error).
  for (const std::string& name : state.records.front()) {
    if (InvalidUtf8At(name) != std::string::npos)
      throw InputError(source, "row 1 (header), column " + std::to_string(table.header.size() + 1) +
                                   ": is not valid UTF-8 (save the file as UTF-8)");
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
    for (size_t i = 0; i < row.cells.size() && row.error.empty(); ++i)
      if (InvalidUtf8At(row.cells[i]) != std::string::npos)
        row.error = "column " + table.header[i] + ": is not valid UTF-8 (save the file as UTF-8)";
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
