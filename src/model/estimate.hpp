// Estimate and TrackEvent: a measured or fitted value with its standard uncertainty, and an event
// of the body's motion located in a recording. The track analysis (vision/track_analysis.hpp)
// produces them; the report (report/video_trials.hpp) prints them and writes them to JSON. Both
// layers see this header, and neither sees the other: the report stays free of OpenCV, and a
// trial's numbers pass from one to the other as they are. SI units.
#pragma once

#include <optional>
#include <string>

namespace uphill {

// A value with its standard uncertainty, in the value's unit. u absent: not meaningful or not
// available. value is NaN for a quantity that was not measured (null in the report's JSON).
struct Estimate {
  double value = 0;
  std::optional<double> u;
};

// An event of the rolling motion, measured from a track or predicted by the fitted motion.
struct TrackEvent {
  std::string kind;    // "release", "turning point", "comes to rest", "falls off", "reaches O"
  Estimate t, x;       // s, m
  std::string method;  // how it was measured, in words; not in the report's JSON (empty when read back)
};

}  // namespace uphill
