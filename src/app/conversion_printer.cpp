#include "app/conversion_printer.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>
#include <numbers>

#include "io/units.hpp"
#include "model/decimal_text.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {


// The longest text of one number below (model/decimal_text.hpp): printf's %.6f of the largest
// double, longer than any %.6g.
constexpr std::size_t kNumberText = kDecimalTextRoom;

// printf's %.6f and %.6g written at p, which has room for kNumberText characters (FixedText and
// GeneralText give printf's characters several times faster: a large batch prints millions).
char* Fixed6(char* p, double v) { return FixedText(p, p + kNumberText, v, 6); }
char* General6(char* p, double v) { return GeneralText(p, p + kNumberText, v, 6); }

char* Copy(char* p, std::string_view s) {
  if (!s.empty()) std::memcpy(p, s.data(), s.size());
  return p + s.size();
}

// Writes a CSV cell at p (room for 2·size + 2 characters), quoted when it holds a comma, a quote
// or a line break.
char* CsvText(char* p, std::string_view s) {
  if (s.find_first_of(",\"\n") == std::string_view::npos) return Copy(p, s);
  *p++ = '"';
  for (char c : s) {
    if (c == '"') *p++ = '"';
    *p++ = c;
  }
  *p++ = '"';
  return p;
}

std::string Pad(const std::string& s, size_t width) {
  return s.size() < width ? s + std::string(width - s.size(), ' ') : s + " ";
}

void PrintSingle(std::ostream& out, const ConvertedRow& row, const std::string& unit) {
  const ConversionResult& r = *row.result;
  const auto deg = [](double rad) { return Printf("%.6f", rad * 180.0 / std::numbers::pi) + " deg"; };
  const auto len = [unit](double m) {
    return Printf("%.9g", ToUnit(m, Dimension::kLength, unit)) + " " + unit;
  };
  const auto line = [&out](const std::string& key, const std::string& value) {
    out << "  " << key << std::string(key.size() < 30 ? 30 - key.size() : 1, ' ') << value << "\n";
  };
  const Scene& s = r.scene;
  out << s.body().Name() << (r.configuration.label.empty() ? "" : " (" + r.configuration.label + ")")
      << (s.rod_radius() > 0 ? " on rods of diameter " + len(2 * s.rod_radius()) : " on line rails")
      << "\n";
  if (const auto crossbar = r.configuration.CrossbarDistance()) line("L (horizontal)", len(*crossbar));
  line("theta (inclination)", deg(s.rails().theta));
  line("alpha (divergence)", deg(s.rails().alpha));
  line("phi (3-D half angle)", deg(s.rails().HalfAngleBetweenRails()));
  if (s.x_eq()) line("X = x_eq (equilibrium)", len(*s.x_eq()));
  line(s.cone() ? "x_fall (apex)" : "x_max (fall-off)", len(s.x_max()));
  if (s.cone()) {
    line("theta0 (critical, fixed alpha)", deg(*s.theta0()));
    line("dz/dx (constant)", Printf("%.9g", -s.cone()->B()));
  }
  if (r.rest) {
    line("x_rest(-mu) (nearest rest)", len(r.rest->low));
    line("x_rest(mu) = Y (farthest)", len(r.rest->high));
  }
  if (r.propagation) {
    line("standard uncertainties", Pad("first order", 16) + "Monte Carlo (" +
                                       std::to_string(r.propagation->trials) + " trials)");
    for (const PropagatedValue* q : r.propagation->Outputs()) {
      const bool is_angle = std::string(q->unit) == "rad";
      const std::string name = q->name;
      const auto show = [&](double v) {
        return is_angle ? Printf("%.3g", v * 180.0 / std::numbers::pi) + " deg"
                        : Printf("%.3g", ToUnit(v, Dimension::kLength, unit)) + " " + unit;
      };
      line("u(" + name + ")", Pad(show(q->u_first_order), 16) + Pad(show(q->u_monte_carlo), 16) +
                                  (q->disagrees ? "first order and MC differ by > 5 %: use MC" : ""));
    }
  }
  for (const PathPoint& p : r.points)
    line("at x = " + len(p.x), "z = " + len(p.z) + ", dz/dx = " + Printf("%.9g", p.dzdx) +
                                   ", R* = " + len(p.r_star) + ", x_M = " + len(p.x_contact));
  for (const std::string& v : r.verdict) out << "  * " << v << "\n";
}

}  // namespace

OptionalColumns ColumnsOf(const ConversionResult& r) {
  return {!r.configuration.label.empty(), r.propagation.has_value(), r.rest.has_value(), r.scene.cone() != nullptr};
}

ConversionPrinter::ConversionPrinter(std::ostream& out, OutputFormat format, bool batch, std::string unit,
                                     OptionalColumns any)
    : out_(out), format_(format), batch_(batch), unit_(std::move(unit)) {
  // ToUnit's division, with the unit looked up once (a batch prints millions of lengths).
  unit_factor_ = UnitFactor(Dimension::kLength, unit_);
  if (unit_factor_ == 0.0) ToUnit(1.0, Dimension::kLength, unit_);  // throws its message
  for (BodyKind kind : {BodyKind::kSphere, BodyKind::kSpheroid, BodyKind::kDoubleCone})
    body_names_[static_cast<std::size_t>(kind)] = Body{kind}.Name();
  if (format_ == OutputFormat::kCsv) csv_.resize(kCsvBlock + 4096);
  std::vector<Column>& cols = columns_;
  if (any.label) cols.push_back({"label", Cell::kLabel});
  cols.push_back({"body", Cell::kBody});
  cols.push_back({"theta_deg", Cell::kTheta});
  cols.push_back({"alpha_deg", Cell::kAlpha});
  cols.push_back({"phi_deg", Cell::kPhi});
  cols.push_back({"X_" + unit_, Cell::kX});
  if (any.uncertainty) {
    cols.push_back({"u_X_" + unit_, Cell::kUX});
    cols.push_back({"u_X_mc_" + unit_, Cell::kUXMc});
  }
  cols.push_back({"x_max_" + unit_, Cell::kXMax});
  if (any.rest) {
    cols.push_back({"x_rest_low_" + unit_, Cell::kRestLow});
    cols.push_back({"x_rest_" + unit_, Cell::kRest});
  }
  if (any.cone) cols.push_back({"theta0_deg", Cell::kTheta0});
  cols.push_back({"rolls_up", Cell::kRollsUp});
  cols.push_back({"note", Cell::kNote});
  if (format_ == OutputFormat::kCsv) {
    out_ << "row";
    for (const Column& c : columns_) out_ << "," << c.header;
    out_ << ",error\n";
  }
}

ConversionPrinter::~ConversionPrinter() = default;

std::size_t ConversionPrinter::CellRoom(const ConversionSummary& v) const {
  return kNumberText + 2 * v.label.size() + 2;
}

char* ConversionPrinter::WriteCell(char* p, Cell cell, const ConversionSummary& v, bool csv) const {
  const auto deg = [](char* q, double rad) { return Fixed6(q, rad * 180.0 / std::numbers::pi); };
  const auto len = [this](char* q, double m) { return General6(q, m / unit_factor_); };
  const auto len_or_dash = [&](const std::optional<double>& m) {
    if (m) return len(p, *m);
    *p = '-';
    return p + 1;
  };
  switch (cell) {
    case Cell::kLabel: return csv ? CsvText(p, v.label) : Copy(p, v.label);
    case Cell::kBody: return Copy(p, body_names_[static_cast<std::size_t>(v.body)]);
    case Cell::kTheta: return deg(p, v.theta);
    case Cell::kAlpha: return deg(p, v.alpha);
    case Cell::kPhi: return deg(p, v.phi);
    case Cell::kX: return len_or_dash(v.x_eq);
    case Cell::kUX: return len_or_dash(v.u_x_eq);
    case Cell::kUXMc: return len_or_dash(v.u_mc_x_eq);
    case Cell::kXMax: return len(p, v.x_max);
    case Cell::kRestLow: return len_or_dash(v.rest ? std::optional<double>(v.rest->low) : std::nullopt);
    case Cell::kRest: return len_or_dash(v.rest ? std::optional<double>(v.rest->high) : std::nullopt);
    case Cell::kTheta0:
      if (v.theta0) return deg(p, *v.theta0);
      *p = '-';
      return p + 1;
    case Cell::kRollsUp: return Copy(p, v.rolls_up ? "yes" : "no");
    case Cell::kNote:
      // Neither part holds a comma or a quote: no CSV quoting.
      if (v.x_eq_beyond_crossbar) p = Copy(p, "X beyond crossbar");
      if (v.uncertainty_disagrees) p = Copy(p, v.x_eq_beyond_crossbar ? "; u: first order != MC" : "u: first order != MC");
      return p;
  }
  return p;
}

std::vector<std::string> ConversionPrinter::Cells(const ConvertedRow& row) const {
  std::optional<ConversionSummary> from_result;
  if (!row.summary && row.result) from_result = Summarize(*row.result);
  const ConversionSummary* v = row.summary ? &*row.summary : from_result ? &*from_result : nullptr;
  std::vector<std::string> line;
  line.reserve(columns_.size() + 2);
  line.push_back(std::to_string(row.row));
  for (const Column& c : columns_) {
    line.emplace_back();
    if (!v) continue;
    std::string& text = line.back();
    text.resize(CellRoom(*v));
    text.resize(static_cast<std::size_t>(WriteCell(text.data(), c.cell, *v, false) - text.data()));
  }
  line.push_back(row.error);
  return line;
}

void ConversionPrinter::Row(const ConvertedRow& row) {
  const std::size_t index = rows_++;
  if (format_ == OutputFormat::kJson) {
    nlohmann::ordered_json j;
    if (batch_) j["row"] = row.row;
    if (row.result) {
      const nlohmann::ordered_json result = ToJson(*row.result);
      for (const auto& [k, v] : result.items()) j[k] = v;
    } else {
      j["error"] = row.error;
    }
    if (!batch_) {
      out_ << j.dump(2) << "\n";
      return;
    }
    // One element of the array as dump(2) of the whole array would indent it.
    std::string text = j.dump(2);
    std::string indented = index == 0 ? "[\n  " : ",\n  ";
    indented.reserve(text.size() + 64);
    for (char ch : text) {
      indented += ch;
      if (ch == '\n') indented += "  ";
    }
    out_ << indented;
    return;
  }
  if (!batch_ && format_ == OutputFormat::kTable) {
    if (row.result) PrintSingle(out_, row, unit_);
    return;
  }
  if (format_ == OutputFormat::kCsv) {
    std::optional<ConversionSummary> from_result;
    if (!row.summary && row.result) from_result = Summarize(*row.result);
    const ConversionSummary* v = row.summary ? &*row.summary : from_result ? &*from_result : nullptr;
    // Room for the line: the row number, every cell, the error (quoted) and the separators.
    const std::size_t room = 24 + columns_.size() * (v ? CellRoom(*v) + 1 : 1) + 2 * row.error.size() + 4;
    if (csv_used_ + room > csv_.size()) {
      FlushCsv();
      if (room > csv_.size()) csv_.resize(room);
    }
    char* p = csv_.data() + csv_used_;
    p = std::to_chars(p, p + 24, row.row).ptr;
    for (const Column& c : columns_) {
      *p++ = ',';
      if (v) p = WriteCell(p, c.cell, *v, true);
    }
    *p++ = ',';
    p = CsvText(p, row.error);
    *p++ = '\n';
    csv_used_ = static_cast<std::size_t>(p - csv_.data());
    if (csv_used_ >= kCsvBlock) FlushCsv();
    return;
  }
  std::vector<std::string> line = Cells(row);
  if (!table_started_) {
    held_.push_back(std::move(line));
    if (held_.size() >= kTableSample) FlushTable();
    return;
  }
  TableLine(line);
}

void ConversionPrinter::FlushCsv() {
  out_.write(csv_.data(), static_cast<std::streamsize>(csv_used_));
  csv_used_ = 0;
}

void ConversionPrinter::FlushTable() {
  std::vector<std::string> header{"row"};
  for (const Column& c : columns_) header.push_back(c.header);
  header.push_back("error");
  // Drop the error column when no row of the sample failed.
  for (const auto& line : held_) error_column_ |= !line.back().empty();
  width_.assign(header.size(), 0);
  for (std::size_t i = 0; i < header.size(); ++i) width_[i] = header[i].size();
  for (const auto& line : held_)
    for (std::size_t i = 0; i < line.size(); ++i) width_[i] = std::max(width_[i], line[i].size());
  table_started_ = true;
  TableLine(header, true);
  for (const auto& line : held_) TableLine(line);
  held_.clear();
}

void ConversionPrinter::TableLine(const std::vector<std::string>& cells, bool header) {
  const std::size_t shown = error_column_ ? cells.size() : cells.size() - 1;
  std::string text;
  for (std::size_t i = 0; i < shown; ++i) {
    text += (i ? "  " : "") + cells[i];
    if (i + 1 < shown) text += std::string(width_[i] > cells[i].size() ? width_[i] - cells[i].size() : 0, ' ');
  }
  if (!error_column_ && !header && !cells.back().empty()) text += "  " + cells.back();
  out_ << text << "\n";
}

void ConversionPrinter::Finish() {
  if (finished_) return;
  finished_ = true;
  FlushCsv();
  if (format_ == OutputFormat::kJson && batch_) out_ << (rows_ ? "\n]\n" : "[]\n");
  if (format_ == OutputFormat::kTable && batch_) {
    if (!table_started_) FlushTable();
    out_ << "(lengths in " << unit_ << ", angles in degrees; X = unstable equilibrium, x_max = fall-off)\n";
  }
}

}  // namespace uphill
