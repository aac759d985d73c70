#include "vision/track_analysis.hpp"

#include <algorithm>
#include <cmath>

#include "internal/track_events.hpp"
#include "internal/track_model_fit.hpp"
#include "internal/track_series.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

using namespace internal;

void RequireOptions(const TrackAnalysisOptions& o) {
  RequirePositiveLength("u_x", o.u_x);
  RequireGravity("g", o.g);
  if (!(o.band_sigmas > 0.0 && std::isfinite(o.band_sigmas))) throw InputError("band_sigmas", "must be > 0");
  if (!(o.huber_sigmas > 0.0 && std::isfinite(o.huber_sigmas))) throw InputError("huber_sigmas", "must be > 0");
  if (o.confirm_frames < 1) throw InputError("confirm_frames", "must be >= 1");
  if (o.reference_frames < 1) throw InputError("reference_frames", "must be >= 1");
  if (o.rest_frames < 2) throw InputError("rest_frames", "must be >= 2");
  if (!(o.tracker_floor_px >= 0.0 && std::isfinite(o.tracker_floor_px)))
    throw InputError("tracker_floor_px", "must be >= 0 (the tracker's systematic error at rest, px)");
  if (!(o.fit_systematic_scale >= 0.0 && std::isfinite(o.fit_systematic_scale)))
    throw InputError("fit_systematic_scale",
                     "must be >= 0 (the share of the tracker's systematic error a fit carries)");
  if (!(o.tracker_blur >= 0.0 && std::isfinite(o.tracker_blur)))
    throw InputError("tracker_blur", "must be >= 0 (the tracker's systematic error per pixel of motion per frame)");
}

// The first frame of a move that stays inside the stated band (k·u_x) but leaves, for
// `confirm_frames` in a row, k times the wander a ball at rest shows in this track: the larger of
// the tracker's systematic error at rest (floor_m, m) and the frames' own jitter (the robust SD
// of successive differences over √2). Unset when the track shows no such move, or gives no scale
// (floor_m and the jitter both 0).
std::optional<int> Creep(const std::vector<double>& x, double floor_m, const TrackAnalysisOptions& o) {
  if (x.size() < 3) return std::nullopt;
  std::vector<double> steps;
  for (std::size_t i = 1; i < x.size(); ++i) steps.push_back(x[i] - x[i - 1]);
  const double centre = Median(steps);
  for (double& d : steps) d = std::abs(d - centre);
  const double wander = std::max(floor_m, 1.4826 * Median(steps) / std::sqrt(2.0));
  if (!(wander > 0)) return std::nullopt;
  return FirstDeparture(x, false, o.band_sigmas * wander, o.confirm_frames, o.reference_frames);
}

}  // namespace

const FittedParameter* TrackFit::Parameter(const std::string& name) const {
  for (const auto& p : parameters)
    if (p.name == name) return &p;
  return nullptr;
}

TrackAnalysis AnalyseTrack(const Track& track, const Scene& scene, const TrackAnalysisOptions& o) {
  RequireOptions(o);
  TrackAnalysis a;
  a.source = track.source;
  a.options = o;
  a.frames = static_cast<int>(track.frames.size());
  if (track.frames.empty()) throw InputError(track.source, "the track has no frames");
  Series s;
  for (std::size_t i = 0; i < track.frames.size(); ++i) {
    // ReadTrack checks these; a Track built in memory (uphill track --analyse) is checked here.
    const TrackFrame& f = track.frames[i];
    const std::string where = track.source + ", row " + std::to_string(f.row);
    if (!std::isfinite(f.t) || (i > 0 && !(f.t > track.frames[i - 1].t)))
      throw InputError(where, "times must be finite and increase");
    if (f.found && !(std::isfinite(f.x) && std::isfinite(f.z)))
      throw InputError(where, "a frame with the ball needs finite x and z");
  }
  for (const TrackFrame& f : track.frames)
    if (f.found) {
      s.t.push_back(f.t);
      s.x.push_back(f.x);
      s.z.push_back(f.z);
      s.u.push_back(f.u);
      s.v.push_back(f.v);
      s.time_u.push_back(f.v * track.row_delay_u);
      s.outline.push_back(f.radius_px > 0 ? f.u_outline_px * scene.body().across / f.radius_px : 0.0);
      s.rows.push_back(f.row);
      a.measured.emplace_back(f.t, f.x);
    }
  a.found = s.size();
  if (a.found == 0)
    throw InputError(track.source, "the ball was not found in any of the " + std::to_string(a.frames) +
                                       " frames (every row has quality 0): nothing to analyse");
  if (a.found < 2)
    throw InputError(track.source, "the ball was found in only 1 of " + std::to_string(a.frames) +
                                       " frames: a track needs at least 2");
  if (a.frames > 1) {
    std::vector<double> steps;
    for (std::size_t i = 1; i < track.frames.size(); ++i) steps.push_back(track.frames[i].t - track.frames[i - 1].t);
    a.frame_interval = Median(steps);
  }
  if (a.found < a.frames)
    a.notes.push_back(std::to_string(a.frames - a.found) + " of " + std::to_string(a.frames) +
                      " frames without the ball (kept as missing, not interpolated)");
  const double sigma = o.u_x, band = o.band_sigmas * o.u_x;
  const int n = s.size();
  // The tracker's systematic error at rest, m: tracker_floor_px at the body's scale (its half-size
  // across the rolling axis over the outline's radius in pixels, the median over the frames).
  // Every frame at rest shares it, so no number of them averages it away: it adds in quadrature
  // to each position estimate's scatter/√n. Where the rails run toward the camera the path is
  // foreshortened and the error along it is larger by 1/cos of that angle; side views (the
  // sector the docs recommend) stay within 20 % of it.
  std::vector<double> radii;
  for (const TrackFrame& f : track.frames)
    if (f.found && f.radius_px > 0) radii.push_back(f.radius_px);
  const double floor_m = radii.empty() ? 0.0 : o.tracker_floor_px * scene.body().across / Median(radii);
  // Where the track states how far its frames' centres depend on the part of the outline their
  // edges came from (u_outline_px), that is this track's own systematic error at rest, shared by
  // the frames like the floor: the larger of the two, the median over the frames [begin, end),
  // a frame that states none counting 0 (where the model measured most of them, the floor stays:
  // the edge fit's spread on a few frames says little of the model's).
  const auto with_floor = [&](Estimate e, int begin, int end) {
    const double outline =
        end > begin ? Median(std::vector<double>(s.outline.begin() + begin, s.outline.begin() + end)) : 0.0;
    e.u = std::hypot(e.u.value_or(0.0), std::max(floor_m, outline));
    return e;
  };
  // Mean ± scatter/√n of the frames [begin, end) within 3σ of their median (a glitch does not
  // count), σ/√n when fewer than 3.
  const auto stationary = [&](int begin, int end) {
    const double m = Median(std::vector<double>(s.x.begin() + begin, s.x.begin() + end));
    std::vector<double> kept;
    for (int i = begin; i < end; ++i)
      if (std::abs(s.x[i] - m) <= 3 * sigma) kept.push_back(s.x[i]);
    if (kept.empty()) kept.push_back(m);
    const auto [mean, sd] = MeanAndSd(kept, 0, static_cast<int>(kept.size()));
    const int count = static_cast<int>(kept.size());
    return std::pair{with_floor(Estimate{mean, (count >= 3 ? sd : sigma) / std::sqrt(count)}, begin, end), sd};
  };

  // Release.
  const std::optional<int> out = FirstDeparture(s.x, false, band, o.confirm_frames, o.reference_frames);
  if (!out) {
    if (const std::optional<int> creep = Creep(s.x, floor_m, o)) {
      // Within the stated band, yet beyond what the tracker's own error lets a ball at rest
      // wander: the ball moved (released late in the clip, or creeping). Its mean is no rest
      // position; the frames before the move are its release.
      const auto [x, sd] = stationary(0, *creep);
      if (*creep >= 3) a.scatter_at_rest = sd;
      a.release = TrackEvent{"release", {s.t[*creep - 1], std::nullopt}, x,
                             "creeps: the last frame before x moved by more than " + Printf("%g", o.band_sigmas) +
                                 " times the tracker's error at rest, t = " + Printf("%.6g", s.t[*creep - 1]) +
                                 " s; position the mean of the " + std::to_string(*creep) + " frames before"};
      a.direction = s.x[*creep] > x.value ? 1 : -1;
      a.fit.unavailable = "the ball moves, but by less than the stated band (" + Mm(band) +
                          ") in this track: too little motion to fit";
      a.notes.push_back("the ball moves from t = " + Printf("%.6g", s.t[*creep]) +
                        " s on, within the stated band: it is not at rest (no measured Y)");
      return a;
    }
    if (n < o.rest_frames) {
      // As few frames as this are no rest: a search that took a place of the table or the rods'
      // meeting point for the body in a few frames, and never found it, would give a position
      // with a tiny scatter (one ray-traced scene: 5 of 30 frames, 160 mm off).
      a.fit.unavailable = "only " + std::to_string(n) + " frames found: a position at rest needs " +
                          std::to_string(o.rest_frames);
      a.notes.push_back(a.fit.unavailable + "; no measured Y");
      return a;
    }
    const auto [x, sd] = stationary(0, n);
    a.scatter_at_rest = sd;
    a.rest = TrackEvent{"comes to rest", {s.t[0], std::nullopt}, x,
                        "never moves: mean of all " + std::to_string(n) +
                            " frames found, u = scatter/sqrt(n) and the tracker's systematic error in quadrature"};
    a.fit.unavailable = "the ball never moves (every frame within " + Mm(band) + " of the first ones): no trajectory to fit";
    a.notes.push_back("the ball stays at rest for the whole track: its position is a measured Y");
    return a;
  }
  const int i_out = *out;
  // The position estimates use the frames within a tighter band, min(k, 3)·σ: the k·σ band also
  // holds the first (last) frames of the motion, which bias the mean and inflate the scatter.
  const double tight = std::min(band, 3 * sigma);
  {
    const int still = std::min(i_out, FirstDeparture(s.x, false, tight, o.confirm_frames, o.reference_frames).value_or(n));
    const auto [x, sd] = stationary(0, still);
    if (still >= 3) a.scatter_at_rest = sd;
    a.release = TrackEvent{"release", {s.t[i_out - 1], std::nullopt}, x,
                           "band: the last frame within " + Mm(band) + " of the start, t = " +
                               Printf("%.6g", s.t[i_out - 1]) + " s; position the mean of the first " +
                               std::to_string(still) + " frames, within " + Mm(tight)};
    a.direction = s.x[i_out] > x.value ? 1 : -1;
    if (i_out < 3) a.notes.push_back("the ball moves from the first frames: the release position rests on " +
                                     std::to_string(i_out) + " frame(s)");
  }

  // Final rest: a steady tail, after the release, not at the fall-off.
  int moving_end = n;  // frames [i_out - 1, moving_end) are the motion
  if (const std::optional<int> tail = FirstDeparture(s.x, true, band, o.confirm_frames, o.reference_frames)) {
    const int r0 = n - *tail;
    bool steady_z = true;
    std::vector<double> zt(s.z.begin() + r0, s.z.end());
    const double zm = Median(zt);
    for (double z : zt) steady_z = steady_z && std::abs(z - zm) <= band;
    const std::optional<RestFit> rest = FitRest(s, r0, n, o.rest_frames);
    if (*tail >= o.rest_frames && r0 > i_out && steady_z && rest && rest->x.value < scene.x_max() - band) {
      a.rest = TrackEvent{"comes to rest", {rest->t, std::nullopt}, with_floor(rest->x, n - rest->frames, n),
                          "fit of the final " + std::to_string(*tail) + " frames within " + Mm(band) +
                              ": constant from t on (" + std::to_string(rest->frames) +
                              " frames), a quadratic approach before; u from the scatter and the tracker's "
                              "systematic error in quadrature"};
      if (!a.scatter_at_rest) a.scatter_at_rest = rest->scatter;
      moving_end = r0;
    }
  }

  // Turning points: a zigzag with the same band and confirmation, on x smoothed by a running
  // median over 2·confirm − 1 frames (a glitch of fewer than `confirm` frames is not an extreme).
  std::vector<double> smooth(n);
  for (int i = 0; i < n; ++i) {
    const int half = o.confirm_frames - 1;
    smooth[i] = Median(std::vector<double>(s.x.begin() + std::max(0, i - half), s.x.begin() + std::min(n, i + half + 1)));
  }
  int dir = a.direction, extreme = i_out, window_begin = 0;
  for (int i = i_out + 1; i < moving_end; ++i) {
    if ((smooth[i] - smooth[extreme]) * dir > 0) {
      extreme = i;
      continue;
    }
    bool reversed = i + o.confirm_frames <= moving_end;
    for (int c = 0; c < o.confirm_frames && reversed; ++c) reversed = (smooth[extreme] - smooth[i + c]) * dir > band;
    if (!reversed) continue;
    std::optional<TrackEvent> e = ParabolaVertex(s, smooth, extreme, 3 * band, dir, sigma, i_out - 1, moving_end - 1);
    if (!e) {
      e = TrackEvent{"turning point", {s.t[extreme], a.frame_interval}, {smooth[extreme], sigma},
                     "the extreme frame (no parabola fits)"};
    }
    a.turning_points.push_back(*e);
    window_begin = extreme;
    while (window_begin < n && s.t[window_begin] < e->t.value) ++window_begin;
    dir = -dir;
    extreme = i;
  }

  // The end: falls off at x_max (moving up) or reaches O (moving down), unless at rest.
  if (!a.rest && n >= 2) {
    double step = 0;
    for (int i = std::max(1, n - 3); i < n; ++i) step = std::max(step, std::abs(s.x[i] - s.x[i - 1]));
    const double tol = band + 2 * step;
    const double last_high = *std::max_element(s.x.end() - std::min(n, o.confirm_frames), s.x.end());
    const double last_low = *std::min_element(s.x.end() - std::min(n, o.confirm_frames), s.x.end());
    const bool falls = dir > 0 && last_high >= scene.x_max() - tol;
    const bool reaches_o = dir < 0 && last_low <= scene.x_low() + tol;
    if (falls || reaches_o) {
      const double edge = falls ? scene.x_max() : scene.x_low();
      int first = n - 1;
      for (int i = std::max(i_out, window_begin); i < n; ++i)
        if (std::abs(s.x[i] - edge) <= band + step) {
          first = i;
          break;
        }
      TrackEvent e{falls ? "falls off" : "reaches O", {s.t[first], a.frame_interval}, {edge, std::nullopt},
                   "the first frame within " + Mm(band + step) + " of " + (falls ? "x_max" : "x_low") +
                       ", u = one frame interval"};
      (falls ? a.fall_off : a.reaches_o) = e;
    }
  }

  // The model fit, from the release (or the last turning point) to the end of the motion.
  int window_end = n;
  if (a.rest && o.fit == TrackFitParameter::kEffectiveG) {
    window_end = moving_end;
    a.fit.notes.push_back("the ball comes to rest, which mu = 0 cannot model: the fit stops where the rest begins "
                          "(fit mu to model it)");
  }
  const double x0_start = a.turning_points.empty() ? a.release->x.value : a.turning_points.back().x.value;
  if (!a.turning_points.empty())
    a.fit.notes.push_back("the fit models the motion after the last turning point (a release from rest there)");
  FitModel(s, window_begin, window_end, dir, scene, o, x0_start, band, &a.fit);

  // Refine the events with the fit where it knows better.
  if (a.fit.available && a.fit.covariance) {
    const FittedParameter* x0 = a.fit.Parameter("x0");
    const FittedParameter* t0 = a.fit.Parameter("t0");
    // The larger of the stated σ's standard error inflated by χ²/ν and the uncertainty to quote.
    const auto inflated = [&](const FittedParameter* p) {
      return std::max(*p->se * std::max(1.0, std::sqrt(a.fit.reduced_chi2)), p->u.value_or(0.0));
    };
    if (a.turning_points.empty()) {
      a.release->method = "model fit (x0, t0); " + a.release->method;
      a.release->t = {t0->value, inflated(t0)};
      a.release->x = {x0->value, inflated(x0)};
    }
    for (const TrackEvent& e : a.fit.model_events)
      for (std::optional<TrackEvent>* end : {&a.fall_off, &a.reaches_o})
        if (*end && (*end)->kind == e.kind) {
          (*end)->t = e.t;
          (*end)->method = "fitted model: t0 + the model's time to get there";
        }
  }
  return a;
}

TrackFitParameter ParseTrackFitParameter(const std::string& text, const std::string& field) {
  if (text == "g") return TrackFitParameter::kEffectiveG;
  if (text == "mu") return TrackFitParameter::kMu;
  throw InputError(field, "must be g (an effective g) or mu (rolling resistance), got '" + text + "'");
}

}  // namespace uphill
