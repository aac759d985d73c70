#include "bench/track_random_analysis.hpp"

#include <cmath>
#include <filesystem>

#include "model/input_error.hpp"
#include "vision/track_analysis.hpp"
#include "vision/track_table.hpp"

namespace uphill::bench {

AnalysisScore ScoreAnalysis(const std::string& track_csv, const FootageCondition& c) {
  AnalysisScore s;
  if (!std::filesystem::exists(track_csv)) {
    s.kind = "no track";
    return s;
  }
  if (c.motion.v0 != 0) {
    s.kind = "a push: not modelled";
    return s;
  }
  TrackAnalysisOptions options;
  options.g = c.motion.g;
  options.fit = c.motion.mu > 0 ? TrackFitParameter::kMu : TrackFitParameter::kEffectiveG;
  TrackAnalysis a;
  try {
    a = AnalyseTrack(ReadTrackFile(track_csv), c.scene, options);
  } catch (const InputError& e) {
    s.kind = e.what();
    return s;
  }
  if (a.direction == 0) {
    if (!a.rest) {
      s.kind = "no rest position";
      return s;
    }
    s.kind = "rest";
    s.pulls.push_back({"Y", a.rest->x.value - c.x0, a.rest->x.u.value_or(0)});
    return s;
  }
  if (!a.fit.available) {
    s.kind = a.fit.unavailable;
    // The release's position (the mean of the frames before the move) is still a stated x0.
    if (a.release && a.release->x.u) {
      s.kind = "release only (" + a.fit.unavailable + ")";
      s.pulls.push_back({"x0", a.release->x.value - c.x0, *a.release->x.u});
    }
    return s;
  }
  s.kind = "fit " + a.fit.fitted;
  const double truth[] = {c.x0, c.release_time, c.motion.mu > 0 ? c.motion.mu : c.motion.g};
  for (size_t i = 0; i < a.fit.parameters.size() && i < 3; ++i) {
    const FittedParameter& p = a.fit.parameters[i];
    s.pulls.push_back(
        {p.name, p.value - truth[i], p.u.value_or(0), p.se_statistical.value_or(0), p.se_systematic.value_or(0)});
  }
  return s;
}

}  // namespace uphill::bench
