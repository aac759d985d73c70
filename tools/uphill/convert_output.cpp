#include "convert_output.hpp"

#include <cstdio>
#include <functional>
#include <numbers>

#include "io/units.hpp"
#include "model/number_text.hpp"

namespace uphill::cli {
namespace {

using io::ConversionResult;


// A column of the table and CSV: header (with unit) and how to get its text from a result.
struct Column {
  std::string header;
  std::function<std::string(const ConversionResult&)> text;
};

std::vector<Column> Columns(const std::vector<ConvertedRow>& rows, const std::string& unit) {
  const auto deg = [](double rad) { return Printf("%.6f", rad * 180.0 / std::numbers::pi); };
  const auto len = [unit](double m) { return Printf("%.6g", io::ToUnit(m, io::Dimension::kLength, unit)); };
  bool any_rest = false, any_u = false, any_cone = false, any_label = false;
  for (const auto& r : rows) {
    if (!r.result) continue;
    any_rest |= r.result->rest.has_value();
    any_u |= r.result->propagation.has_value();
    any_cone |= r.result->scene.cone() != nullptr;
    any_label |= !r.result->configuration.label.empty();
  }
  std::vector<Column> cols;
  if (any_label) cols.push_back({"label", [](const ConversionResult& r) { return r.configuration.label; }});
  cols.push_back({"body", [](const ConversionResult& r) { return r.scene.body().Name(); }});
  cols.push_back({"theta_deg", [deg](const ConversionResult& r) { return deg(r.scene.rails().theta); }});
  cols.push_back({"alpha_deg", [deg](const ConversionResult& r) { return deg(r.scene.rails().alpha); }});
  cols.push_back({"phi_deg", [deg](const ConversionResult& r) {
                    return deg(r.scene.rails().HalfAngleBetweenRails());
                  }});
  cols.push_back({"X_" + unit, [len](const ConversionResult& r) {
                    return r.scene.x_eq() ? len(*r.scene.x_eq()) : std::string("-");
                  }});
  if (any_u) {
    cols.push_back({"u_X_" + unit, [len](const ConversionResult& r) {
                      return r.propagation && r.propagation->x_eq ? len(r.propagation->x_eq->u_first_order)
                                                                  : std::string("-");
                    }});
    cols.push_back({"u_X_mc_" + unit, [len](const ConversionResult& r) {
                      return r.propagation && r.propagation->x_eq ? len(r.propagation->x_eq->u_monte_carlo)
                                                                  : std::string("-");
                    }});
  }
  cols.push_back({"x_max_" + unit, [len](const ConversionResult& r) { return len(r.scene.x_max()); }});
  if (any_rest) {
    cols.push_back({"x_rest_low_" + unit, [len](const ConversionResult& r) {
                      return r.rest ? len(r.rest->low) : std::string("-");
                    }});
    cols.push_back({"x_rest_" + unit, [len](const ConversionResult& r) {
                      return r.rest ? len(r.rest->high) : std::string("-");
                    }});
  }
  if (any_cone)
    cols.push_back({"theta0_deg", [deg](const ConversionResult& r) {
                      return r.scene.theta0() ? deg(*r.scene.theta0()) : std::string("-");
                    }});
  cols.push_back({"rolls_up", [](const ConversionResult& r) { return r.scene.rolls_up() ? "yes" : "no"; }});
  cols.push_back({"note", [](const ConversionResult& r) {
                    std::string note;
                    if (const auto crossbar = r.configuration.CrossbarDistance();
                        crossbar && r.scene.x_eq() && *r.scene.x_eq() > *crossbar)
                      note = "X beyond crossbar";
                    if (r.propagation && r.propagation->disagrees)
                      note += std::string(note.empty() ? "" : "; ") + "u: first order != MC";
                    return note;
                  }});
  return cols;
}

std::string Pad(const std::string& s, size_t width) {
  return s.size() < width ? s + std::string(width - s.size(), ' ') : s + " ";
}

std::string CsvEscape(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

void PrintSingle(std::ostream& out, const ConvertedRow& row, const std::string& unit) {
  const ConversionResult& r = *row.result;
  const auto deg = [](double rad) { return Printf("%.6f", rad * 180.0 / std::numbers::pi) + " deg"; };
  const auto len = [unit](double m) {
    return Printf("%.9g", io::ToUnit(m, io::Dimension::kLength, unit)) + " " + unit;
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
                        : Printf("%.3g", io::ToUnit(v, io::Dimension::kLength, unit)) + " " + unit;
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

void PrintConversion(std::ostream& out, const std::vector<ConvertedRow>& rows, OutputFormat format,
                     bool batch, const std::string& unit) {
  if (format == OutputFormat::kJson) {
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (const auto& row : rows) {
      nlohmann::ordered_json j;
      if (batch) j["row"] = row.row;
      if (row.result) {
        const nlohmann::ordered_json result = io::ToJson(*row.result);
        for (const auto& [k, v] : result.items()) j[k] = v;
      } else {
        j["error"] = row.error;
      }
      all.push_back(j);
    }
    out << (batch ? all.dump(2) : all.at(0).dump(2)) << "\n";
    return;
  }
  if (!batch && format == OutputFormat::kTable) {
    if (rows.at(0).result) PrintSingle(out, rows.at(0), unit);
    return;
  }
  const auto cols = Columns(rows, unit);
  std::vector<std::vector<std::string>> cells;
  std::vector<std::string> header{"row"};
  for (const auto& c : cols) header.push_back(c.header);
  header.push_back("error");
  for (const auto& row : rows) {
    std::vector<std::string> line{std::to_string(row.row)};
    for (const auto& c : cols) line.push_back(row.result ? c.text(*row.result) : "");
    line.push_back(row.error);
    cells.push_back(line);
  }
  if (format == OutputFormat::kCsv) {
    for (size_t i = 0; i < header.size(); ++i) out << (i ? "," : "") << header[i];
    out << "\n";
    for (const auto& line : cells) {
      for (size_t i = 0; i < line.size(); ++i) out << (i ? "," : "") << CsvEscape(line[i]);
      out << "\n";
    }
    return;
  }
  // Table: drop the error column when no row failed; align columns.
  bool any_error = false;
  for (const auto& row : rows) any_error |= !row.error.empty();
  if (!any_error) {
    header.pop_back();
    for (auto& line : cells) line.pop_back();
  }
  std::vector<size_t> width(header.size());
  for (size_t i = 0; i < header.size(); ++i) width[i] = header[i].size();
  for (const auto& line : cells)
    for (size_t i = 0; i < line.size(); ++i) width[i] = std::max(width[i], line[i].size());
  const auto print = [&](const std::vector<std::string>& line) {
    for (size_t i = 0; i < line.size(); ++i) {
      out << (i ? "  " : "") << line[i];
      if (i + 1 < line.size()) out << std::string(width[i] - line[i].size(), ' ');
    }
    out << "\n";
  };
  print(header);
  for (const auto& line : cells) print(line);
  out << "(lengths in " << unit << ", angles in degrees; X = unstable equilibrium, x_max = fall-off)\n";
}

}  // namespace uphill::cli
