#include "vision/track_table.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/csv_table.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

bool Blank(const std::string& cell) {
  return std::all_of(cell.begin(), cell.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r'; });
}

// A plain number (the format fixes the units), via the project's one number parser.
double Number(const CsvTable& table, const CsvRow& row, int column) {
  return ParseQuantity(row.cells[column], Dimension::kDimensionless,
                           CellContext(table, row.row, table.header[column]));
}

void Require(bool ok, const CsvTable& table, const CsvRow& row, int column, const std::string& rule) {
  if (!ok) throw InputError(CellContext(table, row.row, table.header[column]), rule);
}

Track FromTable(const CsvTable& table) {
  const auto& columns = TrackColumns();
  bool header_ok = table.header.size() >= columns.size();
  for (std::size_t c = 0; header_ok && c < columns.size(); ++c) header_ok = table.header[c] == columns[c];
  if (!header_ok)
    throw InputError(table.source + ", row 1",
                     "the header must start with frame,t,u,v,radius_px,x,z,quality (a track written by uphill track)");
  enum { kFrame, kT, kU, kV, kRadius, kX, kZ, kQuality };
  // The optional uncertainty columns, by name after the leading ones (-1: absent).
  const auto optional_column = [&](const std::string& name) {
    const auto at = std::find(table.header.begin() + static_cast<long>(columns.size()), table.header.end(), name);
    return at == table.header.end() ? -1 : static_cast<int>(at - table.header.begin());
  };
  const int u_px_column = optional_column("u_px"), u_x_column = optional_column("u_x"),
            u_outline_column = optional_column("u_outline_px");
  // A standard uncertainty in the column's unit (px, or mm): filled, finite and >= 0.
  const auto uncertainty = [&](const CsvRow& row, int column) {
    if (column < 0) return 0.0;
    Require(!Blank(row.cells[column]), table, row, column, "is empty in a frame with a position");
    const double u = Number(table, row, column);
    Require(u >= 0.0, table, row, column, "must be >= 0, a standard uncertainty (got " + row.cells[column] + ")");
    return u;
  };
  Track track;
  track.source = table.source;
  for (const CsvRow& row : table.rows) {
    if (!row.error.empty()) throw InputError(table.source + ", row " + std::to_string(row.row), row.error);
    TrackFrame f;
    f.row = row.row;
    const double frame = Number(table, row, kFrame);
    Require(frame >= 0 && frame == std::floor(frame) && frame < 1e15, table, row, kFrame,
            "must be a whole number >= 0 (got " + row.cells[kFrame] + ")");
    f.frame = static_cast<long>(frame);
    f.t = Number(table, row, kT);
    if (!track.frames.empty()) {
      const TrackFrame& previous = track.frames.back();
      Require(f.frame > previous.frame, table, row, kFrame,
              "frame numbers must increase (row " + std::to_string(previous.row) + " has frame " +
                  std::to_string(previous.frame) + ")");
      Require(f.t > previous.t, table, row, kT,
              "times must increase (row " + std::to_string(previous.row) + " has t = " + ExactText(previous.t) + " s)");
    }
    int blank = 0;
    for (int c = kU; c <= kZ; ++c) blank += Blank(row.cells[c]);
    const bool quality_blank = Blank(row.cells[kQuality]);
    f.quality = quality_blank ? 0.0 : Number(table, row, kQuality);
    Require(f.quality >= 0.0 && f.quality <= 1.0, table, row, kQuality,
            "must be in [0, 1] (got " + row.cells[kQuality] + ")");
    if (blank == kZ - kU + 1) {
      Require(f.quality == 0.0, table, row, kQuality,
              "must be 0 in a frame without a position (u, v, radius_px, x, z are empty)");
    } else {
      for (int c = kU; c <= kZ; ++c)
        Require(!Blank(row.cells[c]), table, row, c,
                "is empty while other position fields are filled (a lost frame leaves u, v, radius_px, x, z all empty)");
      Require(!quality_blank, table, row, kQuality, "is empty in a frame with a position");
      f.u = Number(table, row, kU);
      f.v = Number(table, row, kV);
      f.radius_px = Number(table, row, kRadius);
      Require(f.radius_px > 0.0, table, row, kRadius, "must be > 0 (got " + row.cells[kRadius] + ")");
      f.x = Number(table, row, kX) * 1e-3;
      f.z = Number(table, row, kZ) * 1e-3;
      f.found = f.quality > 0.0;
      f.u_px = uncertainty(row, u_px_column);
      f.u_x = uncertainty(row, u_x_column) * 1e-3;
      f.u_outline_px = uncertainty(row, u_outline_column);
    }
    track.frames.push_back(f);
  }
  return track;
}

}  // namespace

const std::vector<std::string>& TrackColumns() {
  static const std::vector<std::string> columns = {"frame", "t", "u", "v", "radius_px", "x", "z", "quality"};
  return columns;
}

std::size_t Track::found_count() const {
  return static_cast<std::size_t>(std::count_if(frames.begin(), frames.end(), [](const TrackFrame& f) { return f.found; }));
}

Track ReadTrack(std::istream& in, const std::string& source) { return FromTable(ReadCsv(in, source)); }

Track ReadTrackFile(const std::string& path) {
  Track track = FromTable(ReadCsvFile(path));
  const std::string sidecar = path + ".json";
  std::error_code error;
  if (path == "-" || !std::filesystem::is_regular_file(sidecar, error)) return track;
  std::ifstream in(sidecar);
  const nlohmann::json side = nlohmann::json::parse(in, nullptr, false);
  if (side.is_discarded()) throw InputError(sidecar, "is not valid JSON (the track's sidecar, written by uphill track)");
  if (!side.is_object()) throw InputError(sidecar, "is not a JSON object (the track's sidecar, written by uphill track)");
  if (!side.contains("readout_u_s")) return track;
  const nlohmann::json& u = side["readout_u_s"];
  const nlohmann::json& rows = side.contains("image_height_px") ? side["image_height_px"] : nlohmann::json();
  if (!u.is_number() || !(u.get<double>() >= 0 && std::isfinite(u.get<double>())))
    throw InputError(sidecar + ", readout_u_s", "must be a number >= 0 (s, the measured readout's uncertainty)");
  if (!rows.is_number_integer() || rows.get<long>() <= 0)
    throw InputError(sidecar + ", image_height_px", "must be an integer > 0 with readout_u_s (the rows the readout spans)");
  track.row_delay_u = u.get<double>() / static_cast<double>(rows.get<long>());
  return track;
}

}  // namespace uphill
