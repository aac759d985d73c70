#include "app/calibration_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/output_paths.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

// 6 significant digits: millimetres in the SVG to well below a printer's dot.
std::string Num(double v) { return Printf("%.6g", v); }

}  // namespace

std::vector<ScenePoint> ReadScenePoints(const std::string& path, std::vector<std::string>* names) {
  const CsvTable table = ReadCsvFile(path);
  int u = -1, v = -1, xyz[3] = {-1, -1, -1}, name = -1;
  std::string xyz_unit[3];
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string& h = table.header[i];
    const int column = static_cast<int>(i);
    const auto [stem, unit] = SplitUnitSuffix(h);
    if (h == "u" || h == "u_px") {
      u = column;
    } else if (h == "v" || h == "v_px") {
      v = column;
    } else if ((stem == "x" || stem == "y" || stem == "z") &&
               (unit.empty() || UnitFactor(Dimension::kLength, unit) > 0)) {
      xyz[stem[0] - 'x'] = column;
      xyz_unit[stem[0] - 'x'] = unit;
    } else if (h == "name") {
      name = column;
    } else if (h != "note") {
      throw InputError(CellContext(table, 1, h),
                       "unknown column (expected u, v in pixels, x, y, z with a length unit as in x_mm, "
                       "and optionally name, note)");
    }
  }
  if (u < 0 || v < 0 || xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
    throw InputError(table.source + ", row 1", "the header must have the columns u, v, x, y, z (e.g. u,v,x_mm,y_mm,z_mm)");
  std::vector<ScenePoint> points;
  for (const CsvRow& row : table.rows) {
    if (!row.error.empty()) throw InputError(table.source + ", row " + std::to_string(row.row), row.error);
    ScenePoint p;
    const auto cell = [&](int column) -> const std::string& { return row.cells[column]; };
    const auto where = [&](int column) { return CellContext(table, row.row, table.header[column]); };
    p.label = table.source + ", row " + std::to_string(row.row);
    if (name >= 0 && !cell(name).empty()) p.label += " (" + cell(name) + ")";
    if (names) names->push_back(name >= 0 && !cell(name).empty() ? cell(name) : "row " + std::to_string(row.row));
    p.pixel = {ParseQuantity(cell(u), Dimension::kDimensionless, where(u)),
               ParseQuantity(cell(v), Dimension::kDimensionless, where(v))};
    for (int k = 0; k < 3; ++k)
      p.position[k] = ParseQuantity(cell(xyz[k]), Dimension::kLength, where(xyz[k]), xyz_unit[k]);
    points.push_back(p);
  }
  return points;
}

std::string ChessboardTargetSvg(const ChessboardTarget& t) {
  const double s = t.square * 1000;  // mm
  const int nx = t.cols + 1, ny = t.rows + 1;
  const double w = (nx + 2) * s, h = (ny + 2) * s;
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<!-- uphill calibrate target: " << t.cols << "x" << t.rows << " inner corners, " << Num(s)
      << " mm squares. Print at 100 % (no scaling) and measure a square before calibrating. -->\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Num(w) << "mm\" height=\"" << Num(h)
      << "mm\" viewBox=\"0 0 " << Num(w) << " " << Num(h) << "\">\n"
      << "<rect width=\"" << Num(w) << "\" height=\"" << Num(h) << "\" fill=\"white\"/>\n";
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if ((i + j) % 2 == 0)
        svg << "<rect x=\"" << Num((i + 1) * s) << "\" y=\"" << Num((j + 1) * s) << "\" width=\"" << Num(s)
            << "\" height=\"" << Num(s) << "\" fill=\"black\"/>\n";
  svg << "</svg>\n";
  return svg.str();
}

TargetPng ChessboardTargetPng(const ChessboardTarget& target, double dpi) {
  TargetPng out;
  // Clamped before the conversion to int (a huge dpi must not overflow it); ChessboardTargetImage
  // refuses anything outside 4 to 1000.
  out.pixels_per_square = static_cast<int>(std::clamp(std::round(target.square / 0.0254 * dpi), 0.0, 1e6));
  const cv::Mat image = ChessboardTargetImage(target, out.pixels_per_square);
  std::vector<uchar> png;
  cv::imencode(".png", image, png);
  out.bytes.assign(reinterpret_cast<const char*>(png.data()), png.size());
  out.width = image.cols;
  out.height = image.rows;
  return out;
}

std::string WriteChessboardTarget(const std::string& path, const ChessboardTarget& t, double dpi) {
  const std::string folder = std::filesystem::path(path).parent_path().string();
  if (std::filesystem::path(path).extension() == ".svg") {
    const std::string svg = ChessboardTargetSvg(t);
    OutputPaths::CreateFolders(folder);
    WriteFileAtomically(path, svg);
    return "print at 100 % (no \"fit to page\"), then measure a square: it must be " + Num(t.square * 1000) +
           " mm (give the measured value to --square)";
  }
  const TargetPng png = ChessboardTargetPng(t, dpi);  // refuses a dpi out of range before any folder is made
  OutputPaths::CreateFolders(folder);
  WriteFileAtomically(path, png.bytes);
  return std::to_string(png.width) + " × " + std::to_string(png.height) + " px, " + std::to_string(png.pixels_per_square) +
         " px per square; print at " + Num(dpi) + " dpi so that a square measures " + Num(t.square * 1000) +
         " mm (measure it and give the measured value to --square)";
}

}  // namespace uphill
