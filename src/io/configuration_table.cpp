#include "io/configuration_table.hpp"

#include <algorithm>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill::io {

ConfigurationTable::ConfigurationTable(const CsvTable& table) : table_(table) {
  const auto& known = ConfigurationFieldNames();
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string base = SplitUnitSuffix(table.header[i]).first;
    if (base == "note") continue;
    if (std::find(known.begin(), known.end(), base) == known.end())
      throw InputError(CellContext(table, 1, table.header[i]),
                       "unknown column (see README.md, 'Batch CSV of convert', for the accepted names)");
    if (!field_column_.emplace(base, static_cast<int>(i)).second)
      throw InputError(CellContext(table, 1, table.header[i]), "gives '" + base + "' a second time");
  }
}

FieldSource ConfigurationTable::RowSource(const CsvRow& row, const FieldSource* defaults) const {
  FieldSource source;
  source.lookup = [this, &row, defaults](const std::string& name) -> std::optional<FieldSource::Field> {
    if (auto it = field_column_.find(name); it != field_column_.end()) {
      const std::string& cell = row.cells[it->second];
      if (cell.find_first_not_of(" \t") != std::string::npos)
        return FieldSource::Field{cell, SplitUnitSuffix(table_.header[it->second]).second};
    }
    return defaults ? defaults->lookup(name) : std::nullopt;
  };
  source.context = [this, &row, defaults](const std::string& name) {
    if (auto it = field_column_.find(name); it != field_column_.end())
      return CellContext(table_, row.row, table_.header[it->second]);
    return table_.source + ", row " + std::to_string(row.row) + ": " +
           (defaults ? defaults->context(name) : name + " (no such column)");
  };
  return source;
}

}  // namespace uphill::io
