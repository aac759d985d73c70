// What `uphill analyse-track` makes of the core tracker's track of a random draw
// (bench/track_random.hpp), against the draw's truth: the measurement the lab takes from a video.
//
// Truth: the drawn FootageCondition (x0, the release time, g, μ), which posed the rendered body
// through uphill::Motion; none of it comes from the tracker or the analysis.
//  - A body at rest: the analysis' rest position (its Y) against x0, with its stated u.
//  - A release from rest (rolling up or down): the fitted x0, t0 and g (μ = 0) or μ against the
//    truth, each as a pull (fitted − true)/u with the u the analysis states (FittedParameter::u).
//  - A push (v0 ≠ 0): not scored; the analysis models a release from rest.
#pragma once

#include <string>
#include <vector>

#include "footage/footage_clip.hpp"

namespace uphill::bench {

struct AnalysisPull {
  std::string name;  // "Y" (a rest position), "x0", "t0", "g", "mu"
  double error = 0;  // fitted − true, SI (m, s, m/s², 1)
  double u = 0;      // the stated standard uncertainty, SI; 0 when none was stated
  // A fitted parameter's two parts of u (FittedParameter::se_statistical, se_systematic), so that
  // the pulls under another size of the tracker's systematic error can be computed from the
  // --json output without tracking again; 0 for a position at rest.
  double u_statistical = 0, u_systematic = 0;
  double Pull() const { return u > 0 ? error / u : INFINITY; }
};

struct AnalysisScore {
  // "rest", "fit g", "fit mu", "release only (why no fit)" (x0 alone, from the frames before the
  // move), or why there are no pulls ("a push: not modelled", the analysis' own reason, "no
  // track").
  std::string kind;
  std::vector<AnalysisPull> pulls;
};

// Analyses the track file `track_csv` (with its sidecar) with the defaults of `uphill
// analyse-track` (μ fitted where the draw has rolling resistance) and scores it.
AnalysisScore ScoreAnalysis(const std::string& track_csv, const FootageCondition& condition);

}  // namespace uphill::bench
