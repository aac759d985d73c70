#include "app/convert_batch.hpp"

#include <fast_float/fast_float.h>

#include <cmath>
#include <memory>
#include <unordered_map>

#include "io/configuration_table.hpp"
#include "io/csv_records.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

// The flags' defaults looked up once for every field name (they are the same for every row; a
// batch asks for them millions of times).
FieldSource Cached(const FieldSource& defaults) {
  auto fields = std::make_shared<std::unordered_map<std::string, std::optional<FieldSource::Field>>>();
  auto contexts = std::make_shared<std::unordered_map<std::string, std::string>>();
  for (const std::string& name : ConfigurationFieldNames()) {
    (*fields)[name] = defaults.lookup(name);
    (*contexts)[name] = defaults.context(name);
  }
  FieldSource cached;
  cached.lookup = [fields, defaults](const std::string& name) -> std::optional<FieldSource::Field> {
    const auto it = fields->find(name);
    return it != fields->end() ? it->second : defaults.lookup(name);
  };
  cached.context = [contexts, defaults](const std::string& name) {
    const auto it = contexts->find(name);
    return it != contexts->end() ? it->second : defaults.context(name);
  };
  return cached;
}

// Rows that differ from an earlier one only in their numbers. When every column of the file is a
// number with its unit in the header (L_mm, u_D_mm, ...) or `note`, a row whose cells are all plain
// numbers needs no parsing of field names, units or defaults: it is the configuration of the
// first such row (parsed in full, ParseConfiguration) with the numbers replaced
// (SetNumericField). Any other row - an empty or non-numeric cell, a value the model refuses -
// is parsed in full, so that its result or its error is exactly the general path's.
class NumericRows {
 public:
  explicit NumericRows(const std::vector<std::string>& header) {
    for (const std::string& column : header) {
      const auto [name, unit] = SplitUnitSuffix(column);
      if (name == "note") {
        columns_.push_back({"", 0.0});
        continue;
      }
      const auto dimension = NumericFieldDimension(name);
      const double factor = dimension && !unit.empty() ? UnitFactor(*dimension, unit) : 0.0;
      if (factor == 0.0) return;  // a text column, or units in the cells: every row in full
      columns_.push_back({name, factor});
    }
    usable_ = true;
  }

  // The configuration of `cells` if this row can take the short path (and a template exists).
  std::optional<Configuration> Of(const std::vector<std::string_view>& cells) const {
    if (!usable_ || !first_) return std::nullopt;
    Configuration c = *first_;
    for (std::size_t j = 0; j < cells.size(); ++j) {
      if (columns_[j].name.empty()) continue;
      double number = 0;
      if (!Plain(cells[j], &number)) return std::nullopt;
      const double si = number * columns_[j].factor;  // as ParseQuantity
      if (!std::isfinite(si) || !SetNumericField(c, columns_[j].name, si)) return std::nullopt;
    }
    return c;
  }

  // Offers a row parsed in full as the template of the later ones.
  void Offer(const std::vector<std::string_view>& cells, const Configuration& c) {
    if (!usable_ || first_) return;
    double number = 0;
    for (std::size_t j = 0; j < cells.size(); ++j)
      if (!columns_[j].name.empty() && !Plain(cells[j], &number)) return;
    first_ = c;
  }

 private:
  // A cell that is only a number, as ParseQuantity reads it (an optional '+' before
  // std::from_chars' syntax; fast_float rounds as from_chars does). Zero, subnormal and out-of-range
  // values take the full path, where from_chars' range rules apply.
  static bool Plain(std::string_view cell, double* number) {
    const char* begin = cell.data();
    const char* end = begin + cell.size();
    if (begin < end && *begin == '+') {
      ++begin;
      if (begin < end && (*begin == '-' || *begin == '+')) return false;
    }
    const auto [ptr, ec] = fast_float::from_chars(begin, end, *number);
    return ec == std::errc() && ptr == end && ptr != begin && std::isnormal(*number);
  }
  struct Column {
    std::string name;  // "" for note
    double factor;     // SI per unit of the header's suffix
  };
  std::vector<Column> columns_;
  bool usable_ = false;
  std::optional<Configuration> first_;
};

void Run(CsvRecords& records, const FieldSource& flag_defaults, const ConversionOptions& options,
         const std::function<void(const BatchHeader&)>& on_header,
         const std::function<void(const ConvertedRow&)>& on_row) {
  const ConfigurationTable table(records.header(), records.source());
  const FieldSource defaults = Cached(flag_defaults);
  NumericRows numeric(records.header());
  CsvRecords::Record record;
  bool any = false;
  ConvertedRow out;
  while (records.Next(&record)) {
    if (!any) on_header({records.source(), records.header()});
    any = true;
    out.row = record.row;
    out.result.reset();
    out.error.clear();
    if (record.error.empty()) {
      if (const std::optional<Configuration> c = numeric.Of(record.cells)) {
        try {
          out.result = Convert(*c, options);
          on_row(out);
          continue;
        } catch (const InputError&) {
          // Parsed in full below: the general path names the field and the rule.
        }
      }
    }
    try {
      if (!record.error.empty())
        throw InputError(records.source() + ", row " + std::to_string(record.row), record.error);
      const Configuration c = ParseConfiguration(table.RowSource(record.row, record.cells, &defaults));
      numeric.Offer(record.cells, c);
      try {
        out.result = Convert(c, options);
      } catch (const InputError& e) {
        throw InputError(records.source() + ", row " + std::to_string(record.row) + ": " + e.quantity(), e.rule());
      }
    } catch (const InputError& e) {
      out.error = e.what();
    }
    on_row(out);
  }
  if (!any) throw InputError(records.source(), "has a header but no data rows");
}

}  // namespace

void ConvertBatch(const std::string& path, const FieldSource& defaults, const ConversionOptions& options,
                  const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row) {
  CsvRecords records(path);
  Run(records, defaults, options, on_header, on_row);
}

void ConvertBatch(std::istream& in, const std::string& source, const FieldSource& defaults,
                  const ConversionOptions& options, const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row) {
  CsvRecords records(in, source);
  Run(records, defaults, options, on_header, on_row);
}

}  // namespace uphill
