// ConfigurationTable: a CSV table whose rows are configurations (the batch input of
// `uphill convert`, docs/convert.md "Batch CSV"): columns named by ConfigurationFieldNames(),
// each optionally with a unit suffix (`L_mm`), plus `note` (ignored).
#pragma once

#include <unordered_map>
#include <string>
#include <string_view>
#include <vector>

#include "io/configuration.hpp"
#include "io/csv_table.hpp"

namespace uphill {

class ConfigurationTable {
 public:
  // The columns of a CSV file named `source` (its header row). Throws InputError naming row 1 and
  // the column for an unknown column or a quantity given twice (a misspelt column would
  // otherwise be silently ignored).
  ConfigurationTable(const std::vector<std::string>& header, const std::string& source);
  explicit ConfigurationTable(const CsvTable& table) : ConfigurationTable(table.header, table.source) {}

  // The fields of one row: its non-blank cells (unit from the header suffix, else from the
  // cell), then `defaults` for what the row lacks (nullptr: none). Messages name the cell. The
  // row (its cells) must outlive the returned source.
  FieldSource RowSource(const CsvRow& row, const FieldSource* defaults = nullptr) const;
  FieldSource RowSource(int row, const std::vector<std::string_view>& cells,
                        const FieldSource* defaults = nullptr) const;

 private:
  template <typename Cells>
  FieldSource Source(int row, const Cells& cells, const FieldSource* defaults) const;
  std::vector<std::string> header_;
  std::vector<std::string> units_;  // each column's unit suffix ("" for none)
  std::string source_;
  std::unordered_map<std::string, int> field_column_;  // field name -> column index
};

}  // namespace uphill
