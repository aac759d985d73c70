// The record of a benchmark run: its tables, printed on the terminal as they are measured, and
// one section of the generated docs/benchmarks.md.
//
// docs/benchmarks.md is written only by `uphill bench`: each benchmark replaces its own section
// (between the markers <!-- BEGIN bench NAME --> and <!-- END bench NAME -->) and keeps the
// others, so the file holds the latest run of every benchmark, each with its machine, date and
// versions. The file is replaced atomically (write, fsync, rename): a reader never sees half a
// file. Nobody types timings into it, into the README or into headers.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "bench/machine.hpp"

namespace uphill::bench {

// A table with fixed text widths, so that its rows can be printed as they are measured.
class Table {
 public:
  struct Column {
    std::string name;
    int width;          // text width on the terminal
    bool left = false;  // left-aligned (names); numbers are right-aligned
  };
  explicit Table(std::vector<Column> columns) : columns_(std::move(columns)) {}

  // Prints the header (and remembers the stream for Add).
  void Start(std::ostream& out);
  // Adds a row (one cell per column; missing cells are empty) and prints it if started.
  void Add(std::vector<std::string> cells);
  std::string Markdown() const;
  bool empty() const { return rows_.empty(); }

 private:
  std::string TextRow(const std::vector<std::string>& cells) const;
  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;
  std::ostream* out_ = nullptr;
};

struct Section {
  std::string name;     // "fit": the section of `uphill bench fit`
  std::string command;  // the command line as run
  Machine machine;
  std::vector<std::pair<std::string, std::string>> versions;  // build and peers: (name, version)
  std::string method;   // Markdown: what is measured, how, and against what
  std::vector<std::pair<std::string, const Table*>> tables;  // (caption, table)
  std::vector<std::string> results;  // Markdown lines: the goals and whether they are met
  std::vector<std::string> notes;    // e.g. peers skipped, and why
};

// A section named `name` with the command line, the machine as it is now and the build's
// versions filled in.
Section StartSection(const std::string& name, const std::string& command, const std::string& method);

std::string SectionMarkdown(const Section& section);

// Replaces (or adds, in name order) the section in the file at `path`, atomically. Throws
// std::runtime_error when the file cannot be written.
void WriteSection(const std::filesystem::path& path, const Section& section);

// Where a benchmark writes: `doc` if given, else docs/benchmarks.md of the repository the program
// runs from; "" with *why set when there is none or `disabled` (--no-doc).
std::filesystem::path DocumentPath(const std::string& doc, bool disabled, std::string* why);

// Writes the section where DocumentPath says and tells `out` where (or why not).
void Record(const Section& section, const std::string& doc, bool disabled, std::ostream& out);

}  // namespace uphill::bench
