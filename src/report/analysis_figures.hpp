// The figures of an experiment's fit report, drawn by gnuplot (gnuplot_figure.hpp):
//   fit_y_vs_x     measured Y against theoretical X with error bars in both, y = x, the fitted
//                  straight lines (OLS, York) and the friction model Y = x_rest(μ̂) at each row's
//                  setting
//   fit_offset     Y − X against X: the friction offset, where the physics is visible
//   fit_residuals  residuals Y − fitted against X for OLS (with u(Y) error bars) and for the
//                  friction model
#pragma once

#include <string>
#include <vector>

#include "report/analysis.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill {

std::vector<GnuplotFigure> AnalysisFigures(const ExperimentAnalysis& analysis);
// The names of those figures (whatever the analysis holds), for checking outputs before the work.
std::vector<std::string> AnalysisFigureNames();

}  // namespace uphill
