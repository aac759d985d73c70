// TrackAnalysis: what a measured ball track says about the motion, and the model fitted to it.
//
// Input: a Track (track_table.hpp: t, x, z per frame, lost frames kept as missing) and the Scene
// of the apparatus. Output, SI throughout (m, s):
//
// Events, from the data alone (then refined by the fit where the fit knows better):
//  - release: when the ball starts to move. σ is the stated position uncertainty u_x. Walking
//    forward, a frame is "out" when it leaves the band |x − m| ≤ k·σ around m, the median of the
//    frames before it (at most the first `reference_frames` of them: robust to an outlier and to
//    a slow start), and `confirm_frames` consecutive frames stay out on the same side: one noisy
//    frame is not a release. The position is the mean of the frames before, ± their scatter/√n
//    (σ/√n when fewer than 3); the time is refined by the model fit (t0 ± its standard error):
//    the band only says when the ball had moved k·σ, later than the release.
//  - direction: +1 "up" (away from O, x grows), −1 "down" (toward O).
//  - turning points: reversals of x found by a zigzag with the same k·σ threshold and
//    confirmation on x smoothed by a running median of 2·confirm − 1 frames (a glitch is not an
//    extreme), each refined by a least-squares parabola through the raw frames around the
//    extremum, frames 4σ off it dropped (its vertex: time and position with standard errors from
//    the parabola's covariance).
//  - rest: the final position when the ball comes to rest (a tail of at least `rest_frames`
//    frames in a k·σ band, found like the release walking backward, its z steady too, and not at
//    the fall-off). The body creeps into its rest with a finite deceleration, so the tail is
//    fitted as x_r after a changepoint t_r and x_r + c·(t_r − t)² before (least squares, t_r
//    profiled over the frame times): x_r ± its standard error from the scatter, t_r. This is a
//    measured Y for the fit report. A ball that never leaves its band is at rest from the first
//    frame: rest (the mean ± scatter/√n, from `rest_frames` frames found at least: fewer are no
//    measured Y), no release, no fit, unless it creeps: within the band,
//    it leaves k times the wander a ball at rest shows in this track (the tracker's systematic
//    error at rest below, or the frames' jitter, the robust SD of successive differences over
//    √2, if larger) with the same confirmation. The k·σ band, σ the stated u_x (0.5 mm by
//    default), is far wider than a tracker's error at rest (0.02–0.1 mm), so a ball released late
//    in the clip stays within it. A creeping ball gets a release (the frames before the move),
//    no rest and no fit.
//    Every position estimate at rest (release, rest) adds the tracker's systematic error in
//    quadrature to its scatter: the frames at rest share one bias, which averaging does not
//    reduce; tracker_floor_px at the body's scale (Body::across over the median outline radius
//    in pixels; an underestimate by 1/cos of the path's foreshortening, ≤ 20 % from the side),
//    or, where the track states it and it is larger, the median over those frames of their
//    outline spread (TrackFrame::u_outline_px at the body's scale, 0 in a frame that states
//    none, as where the model measured it: how far the centre moves when one part of the
//    outline is left out, which a body whose limb is half lost against the table shows and the
//    floor does not).
//    Position estimates (release, rest) use the frames within min(k, 3)·σ, not k·σ: the wider
//    band also holds the first frames of the motion.
//  - fall-off: the motion ends up at x_max: the last frames found reach x_max within k·σ plus
//    two frame steps (the tracker loses the ball as it drops, or follows it down at x ≈ x_max).
//    Time from the fitted model (t0 + time to reach x_max, ± propagated) when the fit succeeds,
//    else the first frame that close to x_max ± one frame interval.
//
// The model fit: x(t) of uphill::Motion released from rest at x0 at time t0 (held at x0 before
// t0; after the model's end, fall-off or reaching O, held at the end position: the falling
// ball's x stays at x_max, the path being vertical there) fitted to the measured x(t) by Ceres
// (Levenberg–Marquardt, Huber loss at `huber_sigmas`·σ on the residuals in units of σ), with
// parameters x0, t0 and either
//   kEffectiveG  an effective g (μ = 0, quadrature): absorbs the rolling resistance and any
//                error of the kinetic factor 1 + I/(mR*²) into one time scale; evaluated as
//                x(t; g) = x(t·sqrt(g/g_ref); g_ref) on one Motion, since without friction g
//                only scales time;
//   kMu          the rolling resistance μ at the given g (ODE method, μ ≥ 0).
// After a turning point the motion is a release from rest at the turning point (v = 0 there),
// so the fit window starts at the last turning point (an initial push is not modelled). With
// kEffectiveG a ball that comes to rest cannot be modelled (μ = 0 never stops): the window ends
// where the rest begins, and a note says to fit μ.
// Derivatives: central differences (ceres::NumericDiffCostFunction). Motion is a numerical
// solution (adaptive quadrature, bracketed Newton, or Odeint with event location), not a
// function templated on the scalar type, so ceres::Jet cannot flow through it; its tolerance in
// the fit (1e-12 quadrature, 1e-10 ODE) is far below the relative step 1e-5, so the differences
// carry ~1e-5 relative error at most, plenty for a covariance. Motions are cached by their
// parameters: one Jacobian needs 5 of them, shared by all residual blocks.
// Bounds (Problem::SetParameterLowerBound/UpperBound): x0 stays on the side of X given by the
// measured direction (up: (X, x_max), down: (x_low, X), with a margin of 1e-4·x_max so that no
// difference step crosses X, where the model's direction flips), g_eff > 0, μ ≥ 0; a μ that
// would hold the ball at x0 makes the evaluation fail (Ceres then shortens the step).
// Covariance: ceres::Covariance (dense SVD) of (x0, t0, g or μ); standard errors unscaled (from
// the stated σ) and scaled by sqrt(χ²/ν); χ² and the RMS residual from the raw residuals.
//
// Uncertainty of the fit (FittedParameter::u, the one to quote). A tracker's error is mostly
// systematic: an edge bias that varies along the path (the background behind the outline changes)
// and with the speed (motion blur), so neighbouring frames share it, the residuals are correlated,
// and the part of it that looks like a change of x0, t0 or g is absorbed by the fit and never
// shows in the residuals. Both parts below are sandwich covariances BΣBᵀ of the linearised
// estimator δ = B·e, B = (AᵀWA)⁻¹AᵀW (A: derivatives of the predicted x by the parameters at the
// solution, W: the Huber loss' IRLS weights), for two models Σ of the position errors e:
//  - statistical (se_statistical): Σ_ij = s²·ρ^|i−j|, an AR(1) along the frames of the window, s²
//    the weighted residual variance (÷ (Σw − 3)), ρ their lag-1 autocorrelation (clamped to
//    [0, 0.98]). With uncorrelated residuals it equals se_scaled.
//  - systematic (se_systematic): the tracker's error of one position, 1σ, in raw pixels, is
//    fit_systematic_scale × (tracker_floor_px + tracker_blur × (pixels the centre moves in one
//    frame interval, from the track's u, v)), turned into metres by the track's own scale (the
//    median |Δ(x, z)|/|Δ(u, v)| over steps of ≥ 5 px: the scene's projection as the tracker
//    applied it; a centre that never moves 5 px, a far camera looking along the rails, takes its
//    widest step from the first frame if that reaches 1 px). Errors at
//    positions x_i, x_j are correlated as exp(−|x_i − x_j|/ℓ): equal at the same place (the
//    frames at rest share one bias, which no number of frames averages away). ℓ is not known,
//    so the covariance is averaged over ℓ ∈ {0 (independent), span/256 … span (×2 steps),
//    ∞ (one bias)} with the weights the tracker's errors on random ray-traced scenes show (0.35
//    independent, 0.45 one bias, 0.20 spread over the lengths between; track_fit_errors.hpp):
//    the expected covariance of a bias whose ℓ is drawn from that prior. (The largest variance
//    over ℓ is a worst case, and an even prior over the eleven lengths left g's pulls at an RMS
//    of 0.6–0.7.)
//    A rolling shutter's readout measured or assumed (Track::row_delay_u, from the sidecar) adds to
//    it: every frame's time is uncertain by v_i·row_delay_u, one error shared by all frames, so
//    position i by ẋ_i·v_i·row_delay_u (ẋ_i = −∂x/∂t0), a rank-one covariance added to it.
//  - u = sqrt(se_statistical² + se_systematic²) (the residuals also hold part of the bias: a
//    small double count, on the safe side). The release event quotes max(u, se·sqrt(max(1, χ²/ν))).
// Assumptions: the bias is smooth along the path at the scales tried and of the size the two
// options state; the model is right (fed the true positions, the fit recovers x0, t0, g to 1e-8).
// The defaults (0.08 px, 0.007) are the tracker's error along the path on random ray-traced
// scenes (uphill bench track --random: 255 scenes of 10 seeds, 4,200 moving frames found within a
// pixel of the truth): 0.09 px RMS with under a pixel of smear, growing by about 0.014 px per
// pixel the ball moves during the exposure (0.2 px at 6–10 px of smear), which is 0.007 per pixel
// moved per frame interval at a 180° shutter. Footage with a longer shutter, or a tracker measured
// worse on it, needs larger values (measure them with uphill bench track).
// Accuracy (docs/analyse-track.md "Accuracy", tests/vision_povray_analysis_test.cpp,
// tests/vision_analysis_test.cpp): on 83 fits of the random ray-traced scenes the defaults were
// set on (uphill bench track --random), RMS pulls 0.96, 0.98, 0.97 for x0, t0, g, one |pull|
// beyond 3 of 249, where the statistical part alone misses by more than 3 in 71; on 21 fits of
// fresh scenes 0.86, 0.95, 0.80, none beyond 3; on synthetic tracks with a bias of the stated
// size at the intermediate lengths alone (the hardest case for g) the pulls' RMS is 0.85–1.08.
//
// Accuracy (tests/vision_analysis_test.cpp): on tracks simulated by Motion (a 1-inch ball,
// θ = 3°, α = 40°) with 0.3 mm Gaussian noise at 120 frames/s and lost frames, the fitted x0,
// t0, g or μ, the turning and rest positions and the fall-off time lie within 4 standard errors
// of the truth, with standard errors of the expected size (x0 ≈ σ/√n_rest ≈ 0.04 mm, t0 ≈ 3 ms,
// g ≈ 2 %); over 30 noise realisations the pulls (estimate − truth)/se have an RMS of 0.87–1.02
// (x0, t0, g; x0, t0, μ; turning points): the standard errors are the real scatter.
// Cost: a Ceres fit whose residuals each integrate the motion (quadrature for g, the ODE for μ).
//
// Errors: InputError for an empty track, a track with no frame found, fewer than 2 frames found,
// or options out of range (u_x and g outside model/input_ranges.hpp, k ≤ 0 …). A track that cannot be fitted (the ball
// never moves, too few frames in the window, a scene the chosen model does not cover) is not an
// error: fit.available is false and fit.unavailable says why.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "model/estimate.hpp"
#include "model/scene.hpp"
#include "vision/track_table.hpp"

namespace uphill {

enum class TrackFitParameter { kEffectiveG, kMu };
// "g" or "mu"; InputError naming `field` otherwise.
TrackFitParameter ParseTrackFitParameter(const std::string& text, const std::string& field);

struct TrackAnalysisOptions {
  double g = 9.80665;                                // m/s², the reference g (kMu: the g used), in [1e-3, 1e3]
  TrackFitParameter fit = TrackFitParameter::kEffectiveG;
  double u_x = 0.5e-3;                               // stated position uncertainty σ, m, in [1 nm, 1000 km]
  double band_sigmas = 5.0;                          // k of the k·σ bands
  int confirm_frames = 3;                            // consecutive frames that confirm a change
  int reference_frames = 25;                         // frames of the release band's median
  int rest_frames = 10;                              // a rest lasts at least this many frames found
  double huber_sigmas = 3.0;                         // Huber loss threshold, in σ
  // The tracker's systematic error of one position, 1σ in raw pixels (see "Uncertainty of the
  // fit"): tracker_floor_px + tracker_blur × (pixels the centre moves in one frame interval).
  double tracker_floor_px = 0.08;
  double tracker_blur = 0.007;
  // The share of that error a moving fit's parameters carry (their systematic part is computed
  // with fit_systematic_scale × (tracker_floor_px + tracker_blur × pixels per frame)); positions
  // at rest (release, rest) keep the whole floor. Calibrated on ray-traced fits: with 1, the
  // pulls of x0, t0 and g on 50 fits of four draws not looked at while building the tracker had an
  // RMS of 0.73, 0.87 and 0.69, u too large by a quarter to a third, against 0.96, 0.98 and 0.97
  // on 83 fits of the draws looked at; 0.8 lies between (docs/analyse-track.md, "Accuracy").
  double fit_systematic_scale = 0.8;
};

struct FittedParameter {
  std::string name;    // "x0", "t0", "g" or "mu"
  std::string unit;    // SI unit: "m", "s", "m/s2", ""
  double value = 0;
  std::optional<double> se, se_scaled;  // unscaled (stated σ) and scaled by sqrt(χ²/ν)
  // "Uncertainty of the fit": the statistical part from the residuals (AR(1) sandwich), the
  // tracker's systematic part (averaged over its correlation length), and u = their quadrature
  // sum, the standard uncertainty to quote.
  std::optional<double> se_statistical, se_systematic, u;
};

struct TrackFit {
  bool available = false;
  std::string unavailable;              // why not, when not available
  std::string fitted;                   // "g" or "mu"
  std::vector<FittedParameter> parameters;  // x0, t0, g|mu
  std::optional<Eigen::Matrix3d> covariance;  // unscaled, order as parameters
  double chi2 = 0, reduced_chi2 = 0, rms_residual = 0;  // rms in m
  int dof = 0;
  double residual_lag1 = 0;                     // lag-1 autocorrelation of the residuals (≥ 0)
  double metres_per_pixel = 0;                  // the track's own scale, m/px (0: no pixel coordinates)
  std::vector<double> t, measured, predicted;  // the frames of the window, s and m
  std::vector<double> systematic;               // the tracker's systematic error of each frame, 1σ, m
  std::vector<int> rows;                        // their CSV rows
  std::vector<TrackEvent> model_events;         // events of the fitted motion, absolute times
  std::vector<std::pair<double, double>> curve; // (t, x) of the fitted model, dense, for figures
  int iterations = 0;
  std::string termination;                      // Ceres' summary line
  std::vector<std::string> notes;

  const FittedParameter* Parameter(const std::string& name) const;
};

struct TrackAnalysis {
  std::string source;
  TrackAnalysisOptions options;
  int frames = 0, found = 0;
  double frame_interval = 0;                 // median Δt between consecutive frames, s
  std::optional<double> scatter_at_rest;     // SD of x at the initial (or final) rest, m
  int direction = 0;                         // +1 up (away from O), −1 down, 0 never moves
  std::optional<TrackEvent> release, rest, fall_off, reaches_o;  // reaches_o: rolls back to x_low
  std::vector<TrackEvent> turning_points;
  TrackFit fit;
  std::vector<std::string> notes;
  std::vector<std::pair<double, double>> measured;  // (t, x) of every frame found
};

TrackAnalysis AnalyseTrack(const Track& track, const Scene& scene, const TrackAnalysisOptions& options = {});

}  // namespace uphill
