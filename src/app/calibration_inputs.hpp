// Calibration inputs: the files a user makes for `uphill calibrate` (docs/calibrate.md,
// calibration/README.md) — the points of known position for `calibrate scene --points`, and the
// chessboard target to print for `calibrate target`.
#pragma once

#include <string>
#include <vector>

#include "vision/calibration.hpp"
#include "vision/chessboard_render.hpp"

namespace uphill {

// POINTS.csv: u, v in pixels (columns `u`, `v` or `u_px`, `v_px`), x, y, z in the apparatus
// frame (metres after parsing) with a length unit in the header (`x_mm`) or in every cell
// (`x` = "120mm"); optional `name` (added to the point's label for messages) and `note`
// (ignored). Each point's label is "FILE, row N" (plus " (name)"). Throws InputError naming
// the file, row and column: an unknown column, a missing one, a bad number or unit. `names`
// (optional) receives each point's name as a scene file keeps it: its `name` cell, or "row N".
std::vector<ScenePoint> ReadScenePoints(const std::string& path, std::vector<std::string>* names = nullptr);

// The target as an SVG of exact size in millimetres: (cols + 1) × (rows + 1) squares of
// target.square with a white margin of one square, and a comment saying how to print it.
std::string ChessboardTargetSvg(const ChessboardTarget& target);

// The target as a PNG for a printer of `dpi` dots per inch (a square of target.square spans
// round(square/25.4 mm · dpi) pixels). Throws InputError("pixels per square") unless that is
// 4 to 1000 (ChessboardTargetImage).
struct TargetPng {
  std::string bytes;  // the PNG file
  int width = 0, height = 0, pixels_per_square = 0;
};
TargetPng ChessboardTargetPng(const ChessboardTarget& target, double dpi);

// `calibrate target`: the target written to `path` atomically (its folder created if needed), an
// SVG when `path` ends in .svg, else a PNG for a printer of `dpi` dots per inch; returns the line
// that says how to print it and what a square must then measure. The caller has checked `path`
// (its extension .svg or .png, and that it is no input).
std::string WriteChessboardTarget(const std::string& path, const ChessboardTarget& target, double dpi);

}  // namespace uphill
