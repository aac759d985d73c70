// The report's outputs checked against the experiment's inputs before anything is written, so
// that a report written into (or beside) the experiment folder never replaces a file the
// experiment reads: `uphill report EXP -o DIR` and the page's POST /api/report (EXP/report/) call
// the same check.
//
// Inputs registered (io/output_paths.hpp, compared by device and inode, however the paths are
// spelled): experiment.json, measurements.csv, the camera file, every scene file, every row's
// video, and the folder's video cache (EXP/.uphill-cache: no output inside it). Outputs: the files
// WriteFitReport writes (FitReportFiles) and the figures of every row with a video.
#pragma once

#include <string>

#include "io/experiment.hpp"

namespace uphill {

// Throws InputError naming `flag`, the output file and the input it would replace ("-o
// EXP/fit.json: is the experiment's camera file EXP/fit.json (the same file) …"), or an output
// folder that cannot be written.
// `latex`: the report writes its LaTeX files too (FitReportFiles(true)).
void CheckReportOutputs(const Experiment& experiment, const std::string& directory, const std::string& flag,
                        bool latex = false);

}  // namespace uphill
