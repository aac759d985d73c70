// ConfigurationTable: a CSV table whose rows are configurations (the batch input of
// `uphill convert`, README "Batch CSV of convert"): columns named by ConfigurationFieldNames(),
// each optionally with a unit suffix (`L_mm`), plus `note` (ignored).
#pragma once

#include <map>
#include <string>

#include "io/configuration.hpp"
#include "io/csv_table.hpp"

namespace uphill::io {

class ConfigurationTable {
 public:
  // Keeps a reference to `table`. Throws InputError naming row 1 and the column for an unknown
  // column or a quantity given twice (a misspelt column would otherwise be silently ignored).
  explicit ConfigurationTable(const CsvTable& table);

  // The fields of one row: its non-blank cells (unit from the header suffix, else from the
  // cell), then `defaults` for what the row lacks (nullptr: none). Messages name the cell.
  FieldSource RowSource(const CsvRow& row, const FieldSource* defaults = nullptr) const;

 private:
  const CsvTable& table_;
  std::map<std::string, int> field_column_;  // field name -> column index
};

}  // namespace uphill::io
