#include "io/csv_records.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <set>
#include <stdexcept>

#include "internal/utf8.hpp"
#include "model/input_error.hpp"

namespace uphill {

void OnQuotedField(void* data, std::size_t size, void* self) {
  static_cast<CsvRecords*>(self)->quoted_cells_.emplace_back(static_cast<const char*>(data), size);
}

void OnQuotedRecord(int /*terminator*/, void* self) { static_cast<CsvRecords*>(self)->quoted_done_ = true; }

namespace {

constexpr std::size_t kBlock = std::size_t{1} << 20;

// memchr over [b, e): an empty range (the buffer not yet allocated, so data() may be null)
// finds nothing rather than passing memchr a null pointer.
const char* Find(const char* b, const char* e, char c) {
  return b < e ? static_cast<const char*>(std::memchr(b, c, static_cast<std::size_t>(e - b))) : nullptr;
}

bool IsSpace(char c) { return c == ' ' || c == '\t'; }

std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsSpace(s.back())) s.remove_suffix(1);
  return s;
}

bool AllAscii(const char* b, const char* e) {
  unsigned char any = 0;
  for (const char* p = b; p < e; ++p) any |= static_cast<unsigned char>(*p);
  return any < 0x80;
}

}  // namespace

CsvRecords::CsvRecords(const std::string& path, Options options) : source_(path == "-" ? "<stdin>" : path), options_(options) {
  if (path == "-") {
    fd_ = 0;
  } else {
    fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw InputError(path, "cannot be opened for reading");
    close_fd_ = true;
    posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  }
  ReadHeaderOrRelease();
}

CsvRecords::CsvRecords(std::istream& in, const std::string& source, Options options)
    : source_(source), options_(options), stream_(&in) {
  ReadHeaderOrRelease();
}

CsvRecords::~CsvRecords() { Release(); }

void CsvRecords::Release() {
  if (parser_ready_) csv_free(&parser_);
  parser_ready_ = false;
  if (close_fd_) close(fd_);
  close_fd_ = false;
}

void CsvRecords::ReadHeaderOrRelease() {
  try {
    ReadHeader();
  } catch (...) {
    Release();
    throw;
  }
}

int CsvRecords::Column(const std::string& name) const {
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (header_[i] == name) return static_cast<int>(i);
  return -1;
}

bool CsvRecords::Fill() {
  if (eof_) return false;
  // Keep the unread bytes, at the front.
  if (begin_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    consumed_ += begin_;
    end_ -= begin_;
    begin_ = 0;
  }
  const std::size_t room = std::min(kBlock, buffer_.size() - end_);
  std::size_t got = 0;
  if (stream_) {
    stream_->read(buffer_.data() + end_, static_cast<std::streamsize>(room));
    got = static_cast<std::size_t>(stream_->gcount());
  } else {
    ssize_t n;
    do n = read(fd_, buffer_.data() + end_, room);
    while (n < 0 && errno == EINTR);
    if (n < 0) throw InputError(source_, std::string("cannot be read: ") + std::strerror(errno));
    got = static_cast<std::size_t>(n);
  }
  end_ += got;
  if (got == 0) eof_ = true;
  return got > 0;
}

void CsvRecords::SkipLine(std::size_t from) {
  for (;;) {
    const char* start = buffer_.data() + std::max(from, begin_);
    const char* newline = Find(start, buffer_.data() + end_, '\n');
    if (newline) {
      begin_ = static_cast<std::size_t>(newline - buffer_.data()) + 1;
      return;
    }
    consumed_ += end_;
    begin_ = end_ = from = 0;  // drop what was scanned, unread into memory
    if (!Fill()) return;
  }
}

CsvRecords::Got CsvRecords::Quoted(std::size_t line_begin, Record* record) {
  if (!parser_ready_) {
    if (csv_init(&parser_, CSV_STRICT | CSV_STRICT_FINI) != 0) throw std::runtime_error("libcsv: cannot initialise");
    parser_ready_ = true;
  }
  quoted_cells_.clear();
  quoted_done_ = false;
  std::size_t fed = 0, at = line_begin;
  const auto fail = [&](const std::string& why, bool malformed) {
    csv_free(&parser_);
    parser_ready_ = false;
    quoted_cells_.clear();
    record->error = why;
    record->malformed = malformed;
    record->cells.clear();
    return Got::kRecord;
  };
  for (;;) {
    // Feed libcsv up to the next line end ('\n' or '\r': a lone CR ends a record too, and
    // two records must not share one feed), or what there is of the line.
    const char* start = buffer_.data() + at;
    const char* line_feed = Find(start, buffer_.data() + end_, '\n');
    const char* carriage = Find(start, line_feed ? line_feed : buffer_.data() + end_, '\r');
    const char* newline = carriage ? carriage : line_feed;
    if (!newline && !eof_ && end_ - at < kBlock) {
      const std::size_t offset = at - begin_;
      Fill();
      at = begin_ + offset;
      continue;
    }
    const std::size_t stop = newline ? static_cast<std::size_t>(newline - buffer_.data()) + 1 : end_;
    const std::size_t n = stop - at;
    if (n == 0 && eof_) {
      begin_ = end_;
      if (csv_fini(&parser_, OnQuotedField, OnQuotedRecord, this) != 0)
        return fail("malformed CSV: the input ends inside a quoted field (cut off?)", true);
      if (!quoted_done_) return Got::kEnd;
      break;
    }
    if (csv_parse(&parser_, buffer_.data() + at, n, OnQuotedField, OnQuotedRecord, this) != n) {
      const std::string why = std::string("malformed CSV: ") + csv_strerror(csv_error(&parser_));
      SkipLine(at);
      return fail(why, true);
    }
    fed += n;
    at = stop;
    begin_ = at;
    if (quoted_done_) break;
    if (fed > options_.max_record_bytes) {
      SkipLine(at);
      return fail("is longer than " + std::to_string(options_.max_record_bytes) +
                      " bytes without the end of its quoted field (not a CSV file?)",
                  false);
    }
  }
  if (quoted_cells_.empty()) return Got::kBlank;
  record->cells.assign(quoted_cells_.begin(), quoted_cells_.end());
  non_ascii_ = true;  // rare: let the caller look
  return Got::kRecord;
}

CsvRecords::Got CsvRecords::NextRaw(Record* record) {
  record->cells.clear();
  record->error.clear();
  record->malformed = false;
  non_ascii_ = false;
  for (;;) {
    const char* start = buffer_.data() + begin_;
    const char* newline = Find(start, buffer_.data() + end_, '\n');
    if (!newline) {
      if (end_ - begin_ > options_.max_record_bytes) {
        SkipLine(begin_);
        record->error = "is longer than " + std::to_string(options_.max_record_bytes) +
                        " bytes without a line end (not a CSV file?)";
        return Got::kRecord;
      }
      if (Fill()) continue;
      if (begin_ == end_) return Got::kEnd;  // the last line has no line end: take it as it is
    }
    const char* b = buffer_.data() + begin_;
    const char* e = newline ? newline : buffer_.data() + end_;
    if (static_cast<std::size_t>(e - b) > options_.max_record_bytes) {
      begin_ = static_cast<std::size_t>(e - buffer_.data()) + (newline ? 1 : 0);
      record->error = "is longer than " + std::to_string(options_.max_record_bytes) + " bytes (not a CSV file?)";
      return Got::kRecord;
    }
    const char* content_end = (e > b && e[-1] == '\r') ? e - 1 : e;
    if (Find(b, content_end, '"') || Find(b, content_end, '\r'))
      return Quoted(begin_, record);
    begin_ = static_cast<std::size_t>(e - buffer_.data()) + (newline ? 1 : 0);
    // Split at the commas, in place.
    const char* cell = b;
    for (;;) {
      const char* comma = Find(cell, content_end, ',');
      const char* cell_end = comma ? comma : content_end;
      record->cells.push_back(Trim(std::string_view(cell, cell_end - cell)));
      if (!comma) break;
      cell = cell_end + 1;
    }
    if (record->cells.size() == 1 && record->cells[0].empty()) {  // blank, or only spaces
      record->cells.clear();
      return Got::kBlank;
    }
    non_ascii_ = options_.check_utf8 && !AllAscii(b, content_end);
    return Got::kRecord;
  }
}

void CsvRecords::ReadHeader() {
  // One allocation for the whole read: the longest record and two blocks around it.
  buffer_.resize(options_.max_record_bytes + 2 * kBlock);
  Record record;
  Got got;
  do got = NextRaw(&record);
  while (got == Got::kBlank);
  if (got == Got::kEnd) throw InputError(source_, "is empty (expected a header row)");
  row_ = 1;
  if (!record.error.empty()) throw InputError(source_, "row 1 (header): " + record.error);
  std::set<std::string> seen;
  for (std::string_view raw : record.cells) {
    // CSV files are UTF-8 (data/README.md): a name in another encoding is refused with its column.
    if (internal::InvalidUtf8At(raw) != std::string_view::npos)
      throw InputError(source_, "row 1 (header), column " + std::to_string(header_.size() + 1) +
                                    ": is not valid UTF-8 (save the file as UTF-8)");
    std::string name(Trim(raw));
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first name.
    if (header_.empty() && name.rfind("\xEF\xBB\xBF", 0) == 0) name = std::string(Trim(name.substr(3)));
    if (name.empty())
      throw InputError(source_, "row 1 (header), column " + std::to_string(header_.size() + 1) + ": empty column name");
    if (!seen.insert(name).second) throw InputError(source_, "row 1 (header): duplicate column '" + name + "'");
    header_.push_back(name);
  }
}

void CsvRecords::CheckCells(Record* record) const {
  if (!record->error.empty()) return;
  if (record->cells.size() != header_.size()) {
    record->error = "has " + std::to_string(record->cells.size()) + " fields, the header has " +
                    std::to_string(header_.size());
    return;
  }
  if (!options_.check_utf8 || !non_ascii_) return;
  for (std::size_t i = 0; i < record->cells.size(); ++i)
    if (internal::InvalidUtf8At(record->cells[i]) != std::string_view::npos) {
      record->error = "column " + header_[i] + ": is not valid UTF-8 (save the file as UTF-8)";
      return;
    }
}

bool CsvRecords::Next(Record* record) {
  Got got;
  do got = NextRaw(record);
  while (got == Got::kBlank);
  if (got == Got::kEnd) return false;
  record->row = ++row_;
  CheckCells(record);
  return true;
}

}  // namespace uphill
