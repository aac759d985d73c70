// VideoTrial: what one trial's recording measured, as plain numbers for the fit report (the
// report layer does not see src/vision: app/video_trials.hpp fills these from the tracker and
// the track analysis, vision/track_analysis.hpp, whose contract the numbers keep; the values and
// events are the analysis's own types, model/estimate.hpp). SI units.
//
// In the report (fit_document.hpp, fit_json.hpp):
//  - a row whose Y cell is empty takes the video's rest position as Y ± u(Y);
//  - a row with Y typed too keeps the typed Y in the fits and shows both, flagged when they differ
//    by more than 3 combined standard uncertainties (YComparison);
//  - the table of the trials' motion fits (x0, t0, μ or g_eff with standard errors, χ²/ν);
//  - per trial, the figures of vision's analyse-track: measured x(t) against the fitted model,
//    and the residuals (TrackFigures);
//  - μ from the motions (the weighted mean of the trials' fitted μ) next to μ of the friction
//    fit of the rest positions: a cross-check of the friction model (FrictionCrossCheck).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "model/estimate.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill {

// The data of the per-trial figures (the analyse-track figures, app/track_analysis_output.hpp).
struct TrackFigureData {
  std::vector<std::pair<double, double>> measured;  // (t s, x m) of every frame with the ball
  std::vector<std::pair<double, double>> curve;     // (t, x) of the fitted model, dense
  std::string fitted;                               // "g" or "mu" ("" when no fit)
  bool fit_available = false;
  std::vector<double> fit_t, fit_residual;          // the fit window: s, measured − predicted (m)
  double u_x = 0;                                   // m, the stated σ of a position
  double rms_residual = 0;                          // m
};

struct VideoTrial {
  std::string trial;    // the row's trial label
  int row = 0;          // its spreadsheet row in measurements.csv
  std::string video;    // relative to the experiment folder
  std::string error;    // non-empty: the video could not be analysed (file, rule); nothing below
  bool from_cache = false;
  std::string cache_note;  // one line when a damaged cache entry was tracked again (not in JSON)
  int frames = 0, found = 0;
  double tracker_cpu_seconds = 0;  // the tracker's own CPU time, decoding excluded (0 from the cache)
  bool partial = false;
  std::string partial_reason;
  std::optional<Estimate> rest;                  // x of the final rest, m: the trial's Y
  std::string no_rest;                           // why there is no rest ("never at rest" …)
  std::optional<Estimate> release_x, release_t;  // x0 (m), t0 (s)
  std::vector<TrackEvent> events;
  // The motion fit of x(t): x0, t0 and g_eff (m/s²) or μ.
  bool fit_available = false;
  std::string fit_unavailable;
  std::string fitted;                   // "g" or "mu"
  std::optional<Estimate> fit_value;    // u: analyse-track's u (statistical and the tracker's systematic part)
  double reduced_chi2 = 0;
  int dof = 0;
  std::vector<std::string> notes;
  TrackFigureData figure;
};

// Typed Y against the video's rest position of the same row.
struct YComparison {
  double typed = 0, u_typed = 0, video = 0, u_video = 0;  // m
  double difference = 0, sigma = 0;                       // typed − video, sqrt(u² + u²)
  bool flagged = false;                                   // |difference| > 3·sigma
};
YComparison CompareY(double typed, double u_typed, double video, double u_video);

// The weighted mean of the trials' fitted μ (weights 1/u², u of the mean 1/sqrt(Σ 1/u²), its
// χ²/ν against the mean), from the trials whose fit is of μ and has an uncertainty.
struct MotionMu {
  int trials = 0;
  double mu = 0, u = 0;
  std::optional<double> reduced_chi2;  // when trials ≥ 2
};
std::optional<MotionMu> WeightedMotionMu(const std::vector<VideoTrial>& trials);

// A trial as JSON (SI units; in fit.json's "video_trials" and the video cache's trial.json) and
// back. `with_figure` adds the figure data. VideoTrialFromJson reads the document as input (a
// cache entry may be damaged or edited): every key present with its type, every number finite and
// in range (|x| ≤ 1 km, |t| ≤ 10⁶ s, uncertainties ≥ 0, 0 ≤ found ≤ frames); else InputError
// naming the key and the rule.
nlohmann::json VideoTrialToJson(const VideoTrial& trial, bool with_figure = true);
VideoTrial VideoTrialFromJson(const nlohmann::json& j);

// The two figures of a trial, named `stem` + kXVsT and `stem` + kResiduals (the residuals only
// when the fit is available). Lengths in mm in the figures.
inline constexpr const char* kXVsT = "_x_vs_t";
inline constexpr const char* kResiduals = "_residuals";
std::vector<GnuplotFigure> TrackFigures(const TrackFigureData& data, const std::string& stem,
                                        const std::string& title_suffix = "");

}  // namespace uphill
