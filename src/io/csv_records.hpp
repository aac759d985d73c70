// CsvRecords: a CSV file (or stdin, or a stream) read one record at a time in bounded memory, for
// inputs of any size (`uphill fit --xy`, `uphill convert --batch`; CsvTable is built on it).
//
// Conventions (those of csv_table.hpp): RFC 4180; the first record is the header, whose names are
// trimmed, non-empty, unique and UTF-8 (a UTF-8 byte-order mark is dropped); blank lines (or lines
// of spaces) are skipped; rows are numbered as in a spreadsheet (header = row 1, the first data
// record row 2, a quoted field spanning lines counts as one row). Spaces and tabs around an
// unquoted cell are not part of it.
//
// A record that cannot be read is returned with `error` set and its row number, and reading
// goes on with the next line, so that one bad row costs nothing else:
//   - a different number of fields than the header ("has 3 fields, the header has 4");
//   - a cell that is not UTF-8 (when Options::check_utf8);
//   - malformed quoting (`malformed` is set: libcsv's strict rules);
//   - a record longer than Options::max_record_bytes: "is longer than 1048576 bytes without a line
//     end (not a CSV file?)" - at most that much of it is held, the rest is skipped unread into
//     memory, so a 2 GB line with no newline costs a 1 MiB buffer and a scan;
//   - input that ends inside a quoted field (a file cut off).
// A file cut off in the middle of an unquoted row gives that row with too few fields. Problems
// with the whole input (cannot be opened, empty, a bad header) throw InputError naming it.
//
// How (and why two paths). Input is read in 1 MiB blocks with read(2) into one buffer that holds
// at most one block plus one record: memory is bounded whatever the input's size. A line without
// a double quote or a stray carriage return - every line of a numeric table - is split at its
// commas in place (memchr), the cells handed out as string_views into the buffer: no copy, no
// allocation per row. Any other line goes through libcsv, which owns the quoting rules (quotes,
// escaped quotes, line breaks inside quotes, lone CR line ends); for lines without quotes both
// give the same cells. libcsv steps a state machine byte by byte and copies every field, which on
// a numeric table costs more than reading and converting its numbers together; the fast path
// leaves it the lines only it can read (`uphill bench io` measures the readers end to end).
#pragma once

#include <csv.h>

#include <cstddef>
#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace uphill {

class CsvRecords {
 public:
  struct Options {
    std::size_t max_record_bytes = std::size_t{1} << 20;
    // Refuse cells that are not UTF-8 (each record's bytes are scanned for non-ASCII first).
    // Readers whose every cell must parse as a number may skip it: a non-ASCII byte fails that.
    bool check_utf8 = true;
  };
  struct Record {
    int row = 0;                          // spreadsheet row (header = 1)
    std::vector<std::string_view> cells;  // valid until the next call of Next
    std::string error;                    // non-empty: the record could not be read (see above)
    bool malformed = false;               // error is about quoting (libcsv)
  };

  // `path` "-" reads stdin. Reads the header; throws InputError naming the file.
  CsvRecords(const std::string& path, Options options);
  explicit CsvRecords(const std::string& path) : CsvRecords(path, Options{}) {}
  // Reads from `in` (not owned; must outlive this object), named `source` in messages.
  CsvRecords(std::istream& in, const std::string& source, Options options);
  CsvRecords(std::istream& in, const std::string& source) : CsvRecords(in, source, Options{}) {}
  ~CsvRecords();
  CsvRecords(const CsvRecords&) = delete;
  CsvRecords& operator=(const CsvRecords&) = delete;

  const std::string& source() const { return source_; }
  const std::vector<std::string>& header() const { return header_; }
  // Index of the column named `name`, or -1.
  int Column(const std::string& name) const;

  // The next data record into *record; false at the end of the input.
  bool Next(Record* record);
  // Bytes of the input consumed so far (the header's included).
  std::uint64_t consumed() const { return consumed_ + begin_; }

 private:
  enum class Got { kRecord, kBlank, kEnd };
  // The header, read by the constructors; when it is refused the constructor throws, so no
  // destructor runs: what was acquired (the file, libcsv's buffer) is released first.
  void ReadHeaderOrRelease();
  void ReadHeader();
  void Release();
  bool Fill();  // reads another block; false at the end of the input
  Got NextRaw(Record* record);
  Got Quoted(std::size_t line_begin, Record* record);
  void SkipLine(std::size_t from);  // past the next '\n' at or after `from` (or to the end)
  void CheckCells(Record* record) const;

  std::string source_;
  Options options_;
  int fd_ = -1;
  bool close_fd_ = false;
  std::istream* stream_ = nullptr;
  bool eof_ = false;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;  // unread bytes: buffer_[begin_, end_)
  std::uint64_t consumed_ = 0;       // bytes dropped from the buffer's front so far
  std::vector<std::string> header_;
  int row_ = 0;
  bool non_ascii_ = false;  // the last record has bytes ≥ 0x80 (its cells need the UTF-8 check)
  // libcsv's state for quoted records.
  csv_parser parser_{};
  bool parser_ready_ = false;
  std::vector<std::string> quoted_cells_;
  bool quoted_done_ = false;
  friend void OnQuotedField(void* data, std::size_t size, void* self);
  friend void OnQuotedRecord(int terminator, void* self);
};

}  // namespace uphill
