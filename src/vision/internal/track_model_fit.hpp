// Internal to src/vision: the model fit of AnalyseTrack (track_analysis.hpp): the motion of the
// Scene released from rest at x0 at t0 (motion.hpp), fitted to the frames [begin, end) by Ceres
// with a Huber loss, in x0, t0 and g_eff or μ (TrackAnalysisOptions::fit).
#pragma once

#include "model/scene.hpp"
#include "track_series.hpp"
#include "vision/track_analysis.hpp"

namespace uphill::internal {

// Fills *fit (parameters, covariance, residuals, model events, the fitted curve, notes; or
// `unavailable` with the reason). direction: +1 the ball moves up from x0_start, −1 down; frames
// farther than `band` outside the rails' range are left out (and said so in the notes).
void FitModel(const Series& s, int begin, int end, int direction, const Scene& scene, const TrackAnalysisOptions& o,
              double x0_start, double band, TrackFit* fit);

}  // namespace uphill::internal
