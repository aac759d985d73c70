#include "io/configuration_table.hpp"

#include <algorithm>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill {

namespace {

std::string Context(const std::string& source, int row, const std::string& column) {
  return source + ", row " + std::to_string(row) + ", column " + column;
}

}  // namespace

ConfigurationTable::ConfigurationTable(const std::vector<std::string>& header, const std::string& source)
    : header_(header), source_(source) {
  const auto& known = ConfigurationFieldNames();
  for (size_t i = 0; i < header_.size(); ++i) {
    const auto [base, unit] = SplitUnitSuffix(header_[i]);
    units_.push_back(unit);
    if (base == "note") continue;
    if (std::find(known.begin(), known.end(), base) == known.end())
      throw InputError(Context(source_, 1, header_[i]),
                       "unknown column (see docs/convert.md, 'Batch CSV', for the accepted names)");
    if (!field_column_.emplace(base, static_cast<int>(i)).second)
      throw InputError(Context(source_, 1, header_[i]), "gives '" + base + "' a second time");
  }
}

template <typename Cells>
FieldSource ConfigurationTable::Source(int row, const Cells& cells, const FieldSource* defaults) const {
  FieldSource source;
  source.lookup = [this, &cells, defaults](const std::string& name) -> std::optional<FieldSource::Field> {
    if (auto it = field_column_.find(name); it != field_column_.end()) {
      const std::string_view cell = cells[static_cast<std::size_t>(it->second)];
      if (cell.find_first_not_of(" \t") != std::string_view::npos)
        return FieldSource::Field{std::string(cell), units_[static_cast<std::size_t>(it->second)]};
    }
    if (!defaults) return std::nullopt;
    auto field = defaults->lookup(name);
    if (field) field->is_default = true;
    return field;
  };
  source.context = [this, row, defaults](const std::string& name) {
    if (auto it = field_column_.find(name); it != field_column_.end())
      return Context(source_, row, header_[static_cast<std::size_t>(it->second)]);
    return source_ + ", row " + std::to_string(row) + ": " + (defaults ? defaults->context(name) : name + " (no such column)");
  };
  return source;
}

FieldSource ConfigurationTable::RowSource(const CsvRow& row, const FieldSource* defaults) const {
  return Source(row.row, row.cells, defaults);
}

FieldSource ConfigurationTable::RowSource(int row, const std::vector<std::string_view>& cells,
                                          const FieldSource* defaults) const {
  return Source(row, cells, defaults);
}

}  // namespace uphill
