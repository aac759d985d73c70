// The report for a paper (`uphill report --latex`, docs/fit.md): LaTeX that a document includes
// as it is, written into the report folder beside the HTML report (each file atomically):
//
//   fits.tex                a tabular of the fits: k, c (mm), μ with their standard errors in
//                           siunitx's concise form \num{0.0503(12)} (rounded as the summary
//                           quotes them: quoted_value.hpp), χ²/ν, p-value, AIC; needs
//                           \usepackage{siunitx}
//   trials.tex              a tabular of the trials: θ, α (°), X ± u(X), Y ± u(Y), Y − X (mm), the
//                           excluded rows marked with a footnote mark and their reasons below
//   NAME.pdf                the figures of the report (fit_y_vs_x, fit_offset, fit_residuals;
//                           gnuplot's pdfcairo terminal, fonts embedded), for \includegraphics
//   report-standalone.tex   a minimal article (siunitx, graphicx) that \input's the tables and
//                           includes the figures: `pdflatex report-standalone.tex` in the folder
//
// Every piece of user text (trial labels, reasons, the title) is escaped (LatexEscape), so a
// label such as "t_1 & 50%" prints as typed and cannot break the document.
#pragma once

#include <string>
#include <vector>

#include "report/analysis.hpp"

namespace uphill {

std::string LatexEscape(const std::string& text);

std::string LatexFitsTable(const ExperimentAnalysis& analysis);
std::string LatexTrialsTable(const ExperimentAnalysis& analysis);
std::string LatexStandalone(const ExperimentAnalysis& analysis);

// Writes fits.tex, trials.tex and report-standalone.tex into `directory` (which exists). The
// figures' PDFs are drawn with the report's figures (WriteFitReport with latex). Throws
// EnvironmentError naming the file that cannot be written.
void WriteLatexFiles(const ExperimentAnalysis& analysis, const std::string& directory);

// The .tex files WriteLatexFiles writes (the PDFs are among the figures' files).
std::vector<std::string> LatexFiles();

}  // namespace uphill
