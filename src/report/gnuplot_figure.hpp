// GnuplotFigure: one figure drawn by gnuplot from a generated script kept beside it, so a user can
// restyle it for a paper (`gnuplot NAME.gp` in the output folder rewrites NAME.svg and NAME.png).
//
// Files: NAME.dat (the numbers, whitespace-separated blocks, units in the comments), NAME.gp (the
// script), NAME.svg and NAME.png (and NAME.pdf when asked; a PDF is whole when it ends with %%EOF). Every file is replaced atomically or not at all: the data and
// script by WriteFileAtomically, the images by letting gnuplot write into a private temporary
// folder beside them, then checking that each image is whole (gnuplot exits 0 on a full disk and
// leaves a truncated file: an SVG must end with </svg>, a PNG with its IEND chunk), fsyncing it,
// and renaming it into place. The temporary folder is removed however the call ends. Anything but
// a regular file at an output's name (a folder in the way, a link, a device) is refused before
// anything is written. A figure whose four files are already what the call would write (the same
// data and script, whole images newer than both) is left as it is, without running gnuplot: a
// second report of an unchanged experiment costs no drawing.
#pragma once

#include <string>
#include <vector>

namespace uphill {

struct GnuplotFigure {
  std::string name;     // file stem
  std::string title;    // shown above the figure in documents
  std::string caption;  // what it shows, in plain words
  std::string data;     // content of NAME.dat
  std::string plot;     // gnuplot commands after the preamble (set …; plot 'NAME.dat' …)
  // Also NAME.pdf (gnuplot's pdfcairo terminal, 15 × 10 cm, fonts embedded), for a LaTeX document
  // to \includegraphics as it is (latex_report.hpp).
  bool pdf = false;
};

// Writes the four files into `directory`. Throws EnvironmentError naming the figure and gnuplot's
// complaint when gnuplot is missing (install Debian's gnuplot-nox) or fails, when an image comes
// out incomplete, or when something is in the way.
void RenderFigure(const GnuplotFigure& figure, const std::string& directory);

// The files RenderFigure writes for the figure `name`: NAME.dat, NAME.gp, NAME.svg, NAME.png, and
// NAME.pdf with `pdf`.
std::vector<std::string> FigureFiles(const std::string& name, bool pdf = false);

}  // namespace uphill
