// Paper figures: the use case behind `uphill paper-figures` (docs/paper-figures.md): the seed
// paper's model figures redrawn from uphill's model and motion (SVG + PNG + the gnuplot script
// and data of each, and an index.html gallery), and its two experiment plots from the sample
// experiments. Where docs/physics.md ("The seed paper's errors") shows the paper's formula wrong
// (eq. 8 and its speed: the separatrix, not a release at s), the corrected physics is drawn and
// the paper's curve is added, labelled as such.
#pragma once

#include <string>
#include <vector>

namespace uphill {

// Writes the figures and DIR/index.html into `dir` (created if needed); the experiment plots
// need `data_dir` holding series1-fixed-D and series2-fixed-L ("" leaves them out, and the
// gallery says so). Returns what was written, in order ("DIR/fig_potential.{svg,png}", …,
// "DIR/index.html"). Throws what RenderFigure and LoadExperiment throw (gnuplot missing:
// std::runtime_error; a bad sample folder: InputError).
std::vector<std::string> WritePaperFigures(const std::string& dir, const std::string& data_dir);

}  // namespace uphill
