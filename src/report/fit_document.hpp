// The fit report of an experiment as a Document (document.hpp), and the writer of the report
// folder: report.html (self-contained), report.md, fit.json, and the figures (SVG, PNG, and the
// gnuplot scripts and data beside them). Lengths in mm, angles in degrees; fit.json is SI.
#pragma once

#include <string>
#include <vector>

#include "report/analysis.hpp"
#include "report/document.hpp"
#include "report/figure_pool.hpp"

namespace uphill {

Document FitDocument(const ExperimentAnalysis& analysis, bool with_figures);

// Plain-text rendering of a Document for a terminal (aligned tables), used by `uphill fit`.
std::string RenderText(const Document& document);

// Creates `directory` if needed; every file is written atomically or not at all. The figures are
// drawn concurrently, one gnuplot process per core (figure_pool.hpp), then the documents are
// written. Throws EnvironmentError (figures: gnuplot missing or failing, naming every failed
// figure, the others written; files: the path and the failing call).
void WriteFitReport(const ExperimentAnalysis& analysis, const std::string& directory);
// The same with the caller's pool, which may already be drawing some of the figures (a video
// trial's, submitted as soon as the trial was tracked: VideoTrialFigures(trial, index)); those
// are not drawn twice.
// With `latex` also the LaTeX tables, the standalone document and the figures as PDF
// (latex_report.hpp: `uphill report --latex`).
void WriteFitReport(const ExperimentAnalysis& analysis, const std::string& directory, FigurePool* figures,
                    bool latex = false);
// Creates the report folder (and its parents) if needed; throws EnvironmentError.
void CreateReportFolder(const std::string& directory);
// The names of the files WriteFitReport writes into its folder (with `latex`, those too).
std::vector<std::string> FitReportFiles(bool latex = false);

}  // namespace uphill
