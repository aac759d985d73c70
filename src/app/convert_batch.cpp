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
io::FieldSource Cached(const io::FieldSource& defaults) {
  auto fields = std::make_shared<std::unordered_map<std::string, std::optional<io::FieldSource::Field>>>();
  auto contexts = std::make_shared<std::unordered_map<std::string, std::string>>();
  for (const std::string& name : io::ConfigurationFieldNames()) {
    (*fields)[name] = defaults.lookup(name);
    (*contexts)[name] = defaults.context(name);
  }
  io::FieldSource cached;
  cached.lookup = [fields, defaults](const std::string& name) -> std::optional<io::FieldSource::Field> {
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
// (io::SetNumericField). Any other row - an empty or non-numeric cell, a value the model refuses -
// is parsed in full, so that its result or its error is exactly the general path's.
class NumericRows {
 public:
  explicit NumericRows(const std::vector<std::string>& header) {
    for (const std::string& column : header) {
      const auto [name, unit] = io::SplitUnitSuffix(column);
      if (name == "note") {
        columns_.push_back({"", 0.0});
        continue;
      }
      const auto dimension = io::NumericFieldDimension(name);
      const double factor = dimension && !unit.empty() ? io::UnitFactor(*dimension, unit) : 0.0;
      if (factor == 0.0) return;  // a text column, or units in the cells: every row in full
      columns_.push_back({name, factor});
    }
    usable_ = true;
  }

  // The configuration of `cells` if this row can take the short path (and a template exists).
  std::optional<io::Configuration> Of(const std::vector<std::string_view>& cells) const {
    if (!usable_ || !first_) return std::nullopt;
    io::Configuration c = *first_;
    for (std::size_t j = 0; j < cells.size(); ++j) {
      if (columns_[j].name.empty()) continue;
      double number = 0;
      if (!Plain(cells[j], &number)) return std::nullopt;
      const double si = number * columns_[j].factor;  // as io::ParseQuantity
      if (!std::isfinite(si) || !io::SetNumericField(c, columns_[j].name, si)) return std::nullopt;
    }
    return c;
  }

  // Offers a row parsed in full as the template of the later ones.
  void Offer(const std::vector<std::string_view>& cells, const io::Configuration& c) {
    if (!usable_ || first_) return;
    double number = 0;
    for (std::size_t j = 0; j < cells.size(); ++j)
      if (!columns_[j].name.empty() && !Plain(cells[j], &number)) return;
    first_ = c;
  }

 private:
  // A cell that is only a number, as io::ParseQuantity reads it (an optional '+' before
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
  std::optional<io::Configuration> first_;
};

void Run(io::CsvRecords& records, const io::FieldSource& flag_defaults, const io::ConversionOptions& options,
         const std::function<void(const BatchHeader&)>& on_header,
         const std::function<void(const ConvertedRow&)>& on_row) {
  const io::ConfigurationTable table(records.header(), records.source());
  const io::FieldSource defaults = Cached(flag_defaults);
  NumericRows numeric(records.header());
  io::CsvRecords::Record record;
  bool any = false;
  ConvertedRow out;
  while (records.Next(&record)) {
    if (!any) on_header({records.source(), records.header()});
    any = true;
    out.row = record.row;
    out.result.reset();
    out.error.clear();
    if (record.error.empty()) {
      if (const std::optional<io::Configuration> c = numeric.Of(record.cells)) {
        try {
          out.result = io::Convert(*c, options);
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
      const io::Configuration c = io::ParseConfiguration(table.RowSource(record.row, record.cells, &defaults));
      numeric.Offer(record.cells, c);
      try {
        out.result = io::Convert(c, options);
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

void ConvertBatch(const std::string& path, const io::FieldSource& defaults, const io::ConversionOptions& options,
                  const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row) {
  io::CsvRecords records(path);
  Run(records, defaults, options, on_header, on_row);
}

void ConvertBatch(std::istream& in, const std::string& source, const io::FieldSource& defaults,
                  const io::ConversionOptions& options, const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row) {
  io::CsvRecords records(in, source);
  Run(records, defaults, options, on_header, on_row);
}

}  // namespace uphill
