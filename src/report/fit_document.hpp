// The fit report of an experiment as a Document (document.hpp), and the writer of the report
// folder: report.html (self-contained), report.md, fit.json, and the figures (SVG, PNG, and the
// gnuplot scripts and data beside them). Lengths in mm, angles in degrees; fit.json is SI.
#pragma once

#include <string>
#include <vector>

#include "report/analysis.hpp"
#include "report/document.hpp"

namespace uphill {

Document FitDocument(const ExperimentAnalysis& analysis, bool with_figures);

// Plain-text rendering of a Document for a terminal (aligned tables), used by `uphill fit`.
std::string RenderText(const Document& document);

// Creates `directory` if needed; every file is written atomically or not at all. Throws
// EnvironmentError (figures: gnuplot missing or failing; files: the path and the failing call).
void WriteFitReport(const ExperimentAnalysis& analysis, const std::string& directory);
// The names of the files WriteFitReport writes into its folder.
std::vector<std::string> FitReportFiles();

}  // namespace uphill
