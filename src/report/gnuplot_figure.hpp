// GnuplotFigure: one figure drawn by gnuplot from a generated script kept beside it, so a user can
// restyle it for a paper (`gnuplot NAME.gp` in the output folder rewrites NAME.svg and NAME.png).
//
// Files: NAME.dat (the numbers, whitespace-separated blocks, units in the comments), NAME.gp (the
// script), NAME.svg and NAME.png. Every file is replaced atomically: the data and script by
// WriteFileAtomically, the images by letting gnuplot write temporaries that are renamed only
// when gnuplot succeeds, so a failed run never leaves a half-written figure.
#pragma once

#include <string>

namespace uphill {

struct GnuplotFigure {
  std::string name;     // file stem
  std::string title;    // shown above the figure in documents
  std::string caption;  // what it shows, in plain words
  std::string data;     // content of NAME.dat
  std::string plot;     // gnuplot commands after the preamble (set …; plot 'NAME.dat' …)
};

// Writes the four files into `directory`. Throws std::runtime_error naming the figure and
// gnuplot's complaint when gnuplot is missing (install Debian's gnuplot-nox) or fails.
void RenderFigure(const GnuplotFigure& figure, const std::string& directory);

}  // namespace uphill
