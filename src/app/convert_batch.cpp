#include "app/convert_batch.hpp"

#include <fast_float/fast_float.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <unordered_map>

#include "io/configuration_table.hpp"
#include "io/csv_records.hpp"
#include "io/units.hpp"
#include "model/batch_convert.hpp"
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
        columns_.push_back({std::nullopt, 0.0});
        continue;
      }
      const auto dimension = NumericFieldDimension(name);
      const double factor = dimension && !unit.empty() ? UnitFactor(*dimension, unit) : 0.0;
      if (factor == 0.0) return;  // a text column, or units in the cells: every row in full
      columns_.push_back({FindNumericField(name), factor});
    }
    usable_ = true;
  }

  // The configuration of `cells` if this row can take the short path (and a template exists);
  // valid until the next call. (It is the template with every numeric column replaced: each call
  // sets them all, so a row refused half-way leaves nothing behind for the next.)
  const Configuration* Of(const std::vector<std::string_view>& cells) {
    if (!usable_ || !row_) return nullptr;
    Configuration& c = *row_;
    for (std::size_t j = 0; j < cells.size(); ++j) {
      if (!columns_[j].field) continue;
      double number = 0;
      if (!Plain(cells[j], &number)) return nullptr;
      const double si = number * columns_[j].factor;  // as ParseQuantity
      if (!std::isfinite(si) || !SetNumericField(c, *columns_[j].field, si)) return nullptr;
    }
    return &c;
  }

  // Offers a row parsed in full as the template of the later ones.
  void Offer(const std::vector<std::string_view>& cells, const Configuration& c) {
    if (!usable_ || row_) return;
    double number = 0;
    for (std::size_t j = 0; j < cells.size(); ++j)
      if (columns_[j].field && !Plain(cells[j], &number)) return;
    row_ = c;
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
    std::optional<NumericField> field;  // none for note
    double factor;                      // SI per unit of the header's suffix
  };
  std::vector<Column> columns_;
  bool usable_ = false;
  std::optional<Configuration> row_;  // the template, then the last row's configuration
};

// Rows of the short path gathered for the batch kernels (BatchDetail::kSummary) and handed on
// in input order when the block is evaluated: when it is full, before a row of the full path, and
// at the end.
class SummaryBlock {
 public:
  SummaryBlock(ConvertedRow* out, const std::function<void(const ConvertedRow&)>* on_row)
      : out_(out), on_row_(on_row) {
    for (std::vector<double>* v : {&a_, &b_, &in0_, &in1_, &in2_}) v->reserve(kSummaryBlock);
    rows_.reserve(kSummaryBlock);
  }

  // Whether the kernels give this configuration's summary: a sphere or spheroid on line rails or
  // a sphere on rods, without uncertainties, --mu or --at-x, whose values lie where the model's
  // constructors accept them (Body's factories, Rails::FromApparatus/FromAngles,
  // Scene::MakePath); a row refused here takes the full path, which names its error.
  static bool Covers(const Configuration& c, const ConversionOptions& options) {
    const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
    if (options.mu || !options.at_x.empty() || c.HasUncertainty()) return false;
    const double r = c.rod_radius.value;
    if (!(r >= 0.0) || !std::isfinite(r)) return false;
    if (c.body_kind == BodyKind::kSphere) {
      if (!positive(c.across.value)) return false;
    } else if (c.body_kind == BodyKind::kSpheroid) {
      if (r != 0.0 || !positive(c.across.value) || !positive(c.along.value)) return false;
    } else {
      return false;
    }
    if (!c.from_apparatus)
      return std::isfinite(c.theta.value) && std::isfinite(c.alpha.value) && c.theta.value >= 0.0 &&
             c.theta.value < std::numbers::pi / 2 && c.alpha.value > 0.0 && c.alpha.value < std::numbers::pi;
    const double L = c.L.value, H = c.H.value, D = c.D.value;
    if (!positive(L) || !positive(D) || !std::isfinite(H) || H < 0.0) return false;
    return c.convention == LConvention::kHorizontal || L > std::hypot(H, D / 2);
  }

  // Adds a row that Covers() accepted.
  void Add(int row, const Configuration& c) {
    if (!rows_.empty() && (c.body_kind != body_ || c.from_apparatus != from_apparatus_ || c.convention != convention_))
      Flush();
    body_ = c.body_kind, from_apparatus_ = c.from_apparatus, convention_ = c.convention;
    // A sphere of radius R on rods of radius r is the sphere of radius R + r on line rails (Scene).
    const double a = c.body_kind == BodyKind::kSphere ? c.across.value + c.rod_radius.value : c.across.value;
    const double b = c.body_kind == BodyKind::kSphere ? a : c.along.value;
    rows_.push_back(row);
    a_.push_back(a);
    b_.push_back(b);
    in0_.push_back(c.from_apparatus ? c.L.value : c.theta.value);
    in1_.push_back(c.from_apparatus ? c.H.value : c.alpha.value);
    in2_.push_back(c.from_apparatus ? c.D.value : 0.0);
    if (rows_.size() == kSummaryBlock) Flush();
  }

  void Flush() {
    const std::size_t n = rows_.size();
    if (n == 0) return;
    theta_.resize(n), alpha_.resize(n), phi_.resize(n), B_.resize(n), T_.resize(n), x_eq_.resize(n), x_max_.resize(n);
    const RailsArrays rails{theta_.data(), alpha_.data(), phi_.data(), B_.data(), T_.data()};
    if (from_apparatus_)
      RailsFromApparatusBatch(n, in0_.data(), in1_.data(), in2_.data(), convention_, rails, VectorKernel::kScalar);
    else
      RailsFromAnglesBatch(n, in0_.data(), in1_.data(), rails, VectorKernel::kScalar);
    SpheroidBatch(n, a_.data(), b_.data(), nullptr, B_.data(), T_.data(), x_eq_.data(), x_max_.data(),
                  VectorKernel::kScalar);
    out_->result.reset();
    out_->error.clear();
    ConversionSummary& v = out_->summary.emplace();
    v.body = body_;
    for (std::size_t i = 0; i < n; ++i) {
      out_->row = rows_[i];
      v.theta = theta_[i], v.alpha = alpha_[i], v.phi = phi_[i], v.x_eq = x_eq_[i], v.x_max = x_max_[i];
      v.x_eq_beyond_crossbar =
          from_apparatus_ && x_eq_[i] > HorizontalDistance(in0_[i], in1_[i], in2_[i], convention_);
      (*on_row_)(*out_);
    }
    rows_.clear();
    for (std::vector<double>* v : {&a_, &b_, &in0_, &in1_, &in2_}) v->clear();
  }

 private:
  ConvertedRow* out_;
  const std::function<void(const ConvertedRow&)>* on_row_;
  BodyKind body_ = BodyKind::kSpheroid;
  bool from_apparatus_ = true;
  LConvention convention_ = LConvention::kHorizontal;
  std::vector<int> rows_;
  std::vector<double> a_, b_, in0_, in1_, in2_;  // in: L, H, D or θ, α
  std::vector<double> theta_, alpha_, phi_, B_, T_, x_eq_, x_max_;
};

void Run(CsvRecords& records, const FieldSource& flag_defaults, const ConversionOptions& options,
         const std::function<void(const BatchHeader&)>& on_header,
         const std::function<void(const ConvertedRow&)>& on_row, BatchDetail detail) {
  const ConfigurationTable table(records.header(), records.source());
  const FieldSource defaults = Cached(flag_defaults);
  NumericRows numeric(records.header());
  CsvRecords::Record record;
  bool any = false;
  ConvertedRow out;
  SummaryBlock block(&out, &on_row);
  const bool summary = detail == BatchDetail::kSummary;
  // The result of a row of the full path, handed on in the detail asked for.
  const auto hand_on = [&](std::optional<ConversionResult>&& result) {
    out.result.reset();
    out.summary.reset();
    if (result && summary) out.summary = Summarize(*result);
    else out.result = std::move(result);
    on_row(out);
  };
  while (records.Next(&record)) {
    if (!any) on_header({records.source(), records.header()});
    any = true;
    if (record.error.empty()) {
      if (const Configuration* c = numeric.Of(record.cells)) {
        if (summary && SummaryBlock::Covers(*c, options)) {
          block.Add(record.row, *c);
          continue;
        }
        block.Flush();
        out.row = record.row;
        out.error.clear();
        try {
          hand_on(Convert(*c, options));
          continue;
        } catch (const InputError&) {
          // Parsed in full below: the general path names the field and the rule.
        }
      }
    }
    block.Flush();
    out.row = record.row;
    out.error.clear();
    std::optional<ConversionResult> result;
    try {
      if (!record.error.empty())
        throw InputError(records.source() + ", row " + std::to_string(record.row), record.error);
      const Configuration c = ParseConfiguration(table.RowSource(record.row, record.cells, &defaults));
      numeric.Offer(record.cells, c);
      try {
        result = Convert(c, options);
      } catch (const InputError& e) {
        throw InputError(records.source() + ", row " + std::to_string(record.row) + ": " + e.quantity(), e.rule());
      }
    } catch (const InputError& e) {
      out.error = e.what();
    }
    hand_on(std::move(result));
  }
  block.Flush();
  if (!any) throw InputError(records.source(), "has a header but no data rows");
}

}  // namespace

void ConvertBatch(const std::string& path, const FieldSource& defaults, const ConversionOptions& options,
                  const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row, BatchDetail detail) {
  CsvRecords records(path);
  Run(records, defaults, options, on_header, on_row, detail);
}

void ConvertBatch(std::istream& in, const std::string& source, const FieldSource& defaults,
                  const ConversionOptions& options, const std::function<void(const BatchHeader&)>& on_header,
                  const std::function<void(const ConvertedRow&)>& on_row, BatchDetail detail) {
  CsvRecords records(in, source);
  Run(records, defaults, options, on_header, on_row, detail);
}

}  // namespace uphill
