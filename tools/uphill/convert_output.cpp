#include "convert_output.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <functional>
#include <numbers>

#include "io/units.hpp"
#include "model/number_text.hpp"

namespace uphill::cli {
namespace {


// printf's %.6f and %.6g (std::to_chars with a precision is specified as printf is, and is
// several times faster: a large batch prints millions of these).
std::string Fixed6(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 6).ptr);
}
std::string General6(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6).ptr);
}


std::string Pad(const std::string& s, size_t width) {
  return s.size() < width ? s + std::string(width - s.size(), ' ') : s + " ";
}

// Appends a CSV cell, quoted when it holds a comma, a quote or a line break.
void AppendCsv(std::string* line, const std::string& s) {
  bool plain = true;
  for (char c : s) plain &= c != ',' && c != '"' && c != '\n';
  if (plain) {
    *line += s;
    return;
  }
  *line += '"';
  for (char c : s) {
    if (c == '"') *line += '"';
    *line += c;
  }
  *line += '"';
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
  const double factor = UnitFactor(Dimension::kLength, unit_);
  if (factor == 0.0) ToUnit(1.0, Dimension::kLength, unit_);  // throws its message
  const auto deg = [](double rad) { return Fixed6(rad * 180.0 / std::numbers::pi); };
  const auto len = [factor](double m) { return General6(m / factor); };
  std::vector<Column>& cols = columns_;
  if (any.label) cols.push_back({"label", [](const ConversionResult& r) { return r.configuration.label; }});
  cols.push_back({"body", [](const ConversionResult& r) { return r.scene.body().Name(); }});
  cols.push_back({"theta_deg", [deg](const ConversionResult& r) { return deg(r.scene.rails().theta); }});
  cols.push_back({"alpha_deg", [deg](const ConversionResult& r) { return deg(r.scene.rails().alpha); }});
  cols.push_back({"phi_deg", [deg](const ConversionResult& r) { return deg(r.scene.rails().HalfAngleBetweenRails()); }});
  cols.push_back({"X_" + unit_, [len](const ConversionResult& r) {
                    return r.scene.x_eq() ? len(*r.scene.x_eq()) : std::string("-");
                  }});
  if (any.uncertainty) {
    cols.push_back({"u_X_" + unit_, [len](const ConversionResult& r) {
                      return r.propagation && r.propagation->x_eq ? len(r.propagation->x_eq->u_first_order) : std::string("-");
                    }});
    cols.push_back({"u_X_mc_" + unit_, [len](const ConversionResult& r) {
                      return r.propagation && r.propagation->x_eq ? len(r.propagation->x_eq->u_monte_carlo) : std::string("-");
                    }});
  }
  cols.push_back({"x_max_" + unit_, [len](const ConversionResult& r) { return len(r.scene.x_max()); }});
  if (any.rest) {
    cols.push_back({"x_rest_low_" + unit_, [len](const ConversionResult& r) { return r.rest ? len(r.rest->low) : std::string("-"); }});
    cols.push_back({"x_rest_" + unit_, [len](const ConversionResult& r) { return r.rest ? len(r.rest->high) : std::string("-"); }});
  }
  if (any.cone)
    cols.push_back({"theta0_deg", [deg](const ConversionResult& r) {
                      return r.scene.theta0() ? deg(*r.scene.theta0()) : std::string("-");
                    }});
  cols.push_back({"rolls_up", [](const ConversionResult& r) { return std::string(r.scene.rolls_up() ? "yes" : "no"); }});
  cols.push_back({"note", [](const ConversionResult& r) {
                    std::string note;
                    if (const auto crossbar = r.configuration.CrossbarDistance();
                        crossbar && r.scene.x_eq() && *r.scene.x_eq() > *crossbar)
                      note = "X beyond crossbar";
                    if (r.propagation && r.propagation->disagrees)
                      note += std::string(note.empty() ? "" : "; ") + "u: first order != MC";
                    return note;
                  }});
  if (format_ == OutputFormat::kCsv) {
    out_ << "row";
    for (const Column& c : columns_) out_ << "," << c.header;
    out_ << ",error\n";
  }
}

ConversionPrinter::~ConversionPrinter() = default;

std::vector<std::string> ConversionPrinter::Cells(const ConvertedRow& row) const {
  std::vector<std::string> line;
  line.reserve(columns_.size() + 2);
  line.push_back(std::to_string(row.row));
  for (const Column& c : columns_) line.push_back(row.result ? c.text(*row.result) : "");
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
  std::vector<std::string> line = Cells(row);
  if (format_ == OutputFormat::kCsv) {
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (i) csv_line_ += ',';
      AppendCsv(&csv_line_, line[i]);
    }
    csv_line_ += '\n';
    if (csv_line_.size() >= kCsvBlock) {
      out_.write(csv_line_.data(), static_cast<std::streamsize>(csv_line_.size()));
      csv_line_.clear();
    }
    return;
  }
  if (!table_started_) {
    held_.push_back(std::move(line));
    if (held_.size() >= kTableSample) FlushTable();
    return;
  }
  TableLine(line);
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
  out_.write(csv_line_.data(), static_cast<std::streamsize>(csv_line_.size()));
  csv_line_.clear();
  if (format_ == OutputFormat::kJson && batch_) out_ << (rows_ ? "\n]\n" : "[]\n");
  if (format_ == OutputFormat::kTable && batch_) {
    if (!table_started_) FlushTable();
    out_ << "(lengths in " << unit_ << ", angles in degrees; X = unstable equilibrium, x_max = fall-off)\n";
  }
}

}  // namespace uphill::cli
