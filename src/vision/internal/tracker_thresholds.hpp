// The ball tracker's thresholds (ball_tracker.cpp and the tracker_*.cpp files beside it), in one
// place, each with the reason for its value. Pixels are raw image pixels; "noise" is a sample's
// residual RMS in linear units (outline_fit.hpp). The values were chosen on rendered footage;
// `uphill bench track` measures what they give (docs/bench.md; its results: docs/benchmarks.md).
#pragma once

#include <cstddef>

namespace uphill::internal {

struct TrackerThresholds {
  // The second, narrow pass of a fit, around the first one: the first pass lands within about a
  // pixel, so ±1.5 px holds the outline and keeps the windows small.
  static constexpr double kNarrowHalfWidthPx = 1.5;
  // Ceres iterations of that narrow pass after a coarse search (outline_fit.hpp,
  // FitRequest::iterations): started within a pixel, two iterations reach the minimum.
  static constexpr int kNarrowIterations = 2;
  // Ceres iterations of a pass started at a fit of the same frame or at a checked prediction
  // (within half a pixel or so, where Kaufman's step leaves about a quarter of the offset): the
  // narrow pass where the model measured the frame before (MeasureNear), both passes of a refit,
  // and the refit of a frame at the settled row delay.
  static constexpr int kStartedNearIterations = 1;
  // Frames without the body after which the motion is no longer predicted: beyond a few frames
  // the prediction's error exceeds the search window.
  static constexpr int kHistoryGap = 5;
  // Samples the prediction's parabola is fitted to: enough to average the centres' noise, few
  // enough that a change of motion (release, impact) leaves the window quickly.
  static constexpr std::size_t kHistory = 6;
  // A scene change: the background residual jumps above this many times its usual level (plus
  // 0.01): a bumped camera or a changed exposure, far beyond a frame's noise.
  static constexpr double kSceneChangeFactor = 4;
  // The usual level is never taken below this: H.264 copies static blocks exactly, so the first
  // frames of a clip can show no residual at all, and the first key frame would look like a change.
  // So those frames do not count toward the usual level, and it is first taken from
  // kConfirmFrames others: at a phone's bit rate the encoder copies a still background until
  // the next key frame, which re-encodes a dark cloth 2-4 % off (and the frames after it copy that).
  static constexpr double kUsualResidualFloor = 0.005;
  // Frames that confirm a scene or exposure change: one odd frame (a flash, a dropped frame) is not.
  static constexpr int kConfirmFrames = 3;
  // The fast path (edge_fit.hpp): edge searches per frame, enough to see the outline all round
  // with a few lost to the rails.
  static constexpr int kEdgePoints = 96;
  // Predicted smear over the exposure, in radii, up to which the fast path is tried (its own
  // checks deciding), with the exposure known and with it guessed (a 180° shutter): beyond it the
  // edges' ramps are longer than the edge fit's window and bias its centre.
  static constexpr double kFastMaxBlur = 0.375, kFastMaxBlurGuessed = 0.5;
  // Grey levels across the outline below which an edge is too faint for the edge fit.
  static constexpr double kFastMinContrast = 20;
  // RMS of the edge points about the fitted outline, px: a body whose edges scatter more is
  // patterned or occluded, and needs the model.
  static constexpr double kFastMaxRmsPx = 0.3;
  // Share of the searched rays that must be inliers for the edge fit to be trusted.
  static constexpr double kFastMinAgreement = 0.85;
  // Edge fit against the model at acquisition, px: within this the clip may take the fast path.
  static constexpr double kFastMaxDisagreementPx = 0.5;
  // Share of the fitted rays that must agree with a body found anew (not near a prediction):
  // before the background is known a print near the limb or the rod across it costs rays (a
  // spheroid with a painted band over a rod: 58 % of them), while a patch of the table that
  // happens to fit an outline is told apart by its contrast (the candidates' best is taken).
  static constexpr double kAcquireAgreement = 0.55;
  // The same where the edge fit finds the body's outline there (OutlineFound): a dotted ball's
  // dots near the limb left 0.53 of its rays agreeing with a fit on its centre.
  static constexpr double kAcquireLooseAgreement = 0.45;
  // Noise levels by which a fit's body must stand out of the background to be one (Accept).
  static constexpr double kAcceptMinLevels = 6;
  // The same on that loose route, which counts only where the edge fit then finds the outline
  // (an independent check): a banded ball at rest on a checked cloth held the first fit 10 px off
  // its centre, where it stood out by 5.8 levels, and its outline, found clean all round at 31 grey
  // levels, was not looked for in 23 of its 40 frames.
  static constexpr double kAcquireLooseMinLevels = 4;
  // Noise levels by which a body found anew (not near a prediction) stands out of its
  // surroundings at least (its limb's contrast against what lies behind it): on 80 random scenes
  // every fit that landed on the body stood out by 10.9 or more, and two in three of those that
  // landed elsewhere (a tape mark on a rod, the rods' crossing, a tile's edge) by less.
  static constexpr double kAcquireMinStandOut = 10;
  // ... and by kAcquireMinStandOutSharp where the edge fit found its outline sharp: at least
  // kSharpOutlineShare of the edges found on it, scattered by kFastMaxRmsPx at most. A glossy
  // light-blue ball on a grey-green checked cloth stood out by 8.2 (45 of its 46 edges on the
  // outline, 0.23 px); on the first frames of 153 random scenes the places off a body with such
  // an outline lay within 10 px of it and stood out by 6.6 or less (or by more than 10), and
  // taking them from 5 levels on changed no choice.
  static constexpr double kAcquireMinStandOutSharp = 7, kSharpOutlineShare = 0.95;
  // Grey levels from which an outline whose edges lie on it within kFastMaxRmsPx is found at
  // acquisition (FaintOutlineFound), and then stands out by kAcquireMinStandOutSharp. A dark
  // two-tone ball in dim light stepped by 16.7 levels, its 36 edges on its outline at 0.1 px, and
  // was found in none of its frames; on the first frames of 151 random scenes no place off a
  // body had its edges that sharply on an outline (the closest: 0.87 of them on it at 0.38 px,
  // or 0.65 at 0.29 px), whatever its contrast.
  static constexpr double kAcquireFaintContrast = 10;
  // Noise levels by which the outline's two ends along the rods (path_end_steps.hpp) must each
  // stand out of what lies beyond them for a model fit to be the body (EndsStandOut). On 190
  // random scenes (2787 frames the model measured, none refused by this check), every frame
  // found within a pixel of the truth had both ends at 1.52 levels or more, and the fits left
  // between the rods where the body had been (it fell through the gap) at 0.15–0.45: a
  // two-tone body whose one half matches the table shows that end at 1.5–2 levels, so the
  // threshold sits below it.
  static constexpr double kEndsMinStandOut = 1;
  // The search along the path: the places it proposes, by the colour inside the outline against
  // outside and by the grey step across it (Candidates), and the fits it tries per frame, skipping
  // the places already refused whose pixels did not change (rejected_windows.hpp), so that a
  // body ranked below the rails' own contrast (thick rods inside every outline) is reached
  // within a few frames.
  static constexpr std::size_t kCandidatesByColour = 12, kCandidatesByStep = 4;
  static constexpr int kAcquireFitsPerFrame = 5;
  // In the first frame every candidate and its second start are fitted: a body at rest is there
  // from the start, and the body's own place may rank below a patch of the table that fits an
  // outline too (the best of them is taken, by its contrast).
  static constexpr int kAcquireFitsFirstFrame = 2 * static_cast<int>(kCandidatesByColour + kCandidatesByStep);
  // The share of a colour candidate's score down to which its neighbours along the path belong to
  // its plateau (Candidates): the places whose outline stays on a body score within about 20 % of
  // each other, those whose outline crosses its limb less.
  static constexpr double kPlateauShare = 0.8;
  // CleanOutline: the share of the edge fit's rays within a pixel of its outline, and their RMS,
  // px, for the edge fit to stand in for a model fit without background (a print's stripes near
  // the limb scatter the edges by about 0.35 px and keep about 80 % of them on the outline; a
  // body partly hidden by the rails, or half in shadow, leaves under 75 % of them on it).
  static constexpr double kCleanOutlineAgreement = 0.75, kCleanOutlineRmsPx = 0.5;
  // OutlineFound: the share of the edge points found that lie within a pixel of the outline. On
  // the first frames of 63 random scenes, the search's fits on the body had 0.78–1 of them on it
  // (a striped ball: 0.89, of only 0.58 of its rays), those on a patch of the table or the rods
  // 0.57–0.77 but for one place of a chrome ball's reflection, which was clean all round too.
  static constexpr double kOutlineFoundShare = 0.8;
  // OutlineFound's other way: the share of all the edge fit's rays, and of those searched, within
  // a pixel of the outline. A striped ball's stripes put their edge beside the limb on a quarter
  // of its rays (0.76 of the edges found on it, 0.71 of the rays searched, half of all); on the
  // first frames of 103 random scenes one place off a body reached both, a two-tone spheroid's
  // 3 px off its centre.
  static constexpr double kOutlineMostRays = 0.5, kOutlineMostSearched = 0.7;
  // OutlinePartlyFound: edge points on the outline, at least a quarter of the rays. A grey sphere
  // on a grey checked cloth had 29 of its 30 edges on it (of 59 rays searched, contrast 33 grey
  // levels) while 16 places of the cloth along the path stood out of their surroundings as much
  // (contrast 8-14); on the first frames of 153 random scenes taking such an outline before the
  // stand-out changed no choice.
  static constexpr int kOutlinePartialPoints = kEdgePoints / 4;
  // OnPathAcross: a centre within kOnPathPx of the calibrated path, px, lies on it. On 153 random
  // scenes (calibrated from their chessboard views and apparatus points) the model's frames within
  // 0.3 px of the truth lay within 0.54 px of the path, and 76 of the 109 frames more than 1 px
  // off the truth lay beyond 1 px of it. Where a calibration puts the path farther off, a centre
  // within kOnPathUsualPx of the median height of the last kOnPathFrames frames reported lies on
  // it too (on those scenes the height of the frames within 0.3 px of the truth spread over up to
  // 0.8 px along the rails), and before kOnPathMinFrames were reported, one within
  // kOnPathFirstPx of the path.
  static constexpr double kOnPathPx = 1.0, kOnPathUsualPx = 0.8, kOnPathFirstPx = 2.5;
  static constexpr std::size_t kOnPathFrames = 15, kOnPathMinFrames = 3;
  // Frames left out in a row, their heights within kOnPathUsualPx of each other, that make their
  // height the path's (a calibration farther off than kOnPathFirstPx): on those 153 scenes no
  // ten frames left out in a row did (a print's edge holds the outline for up to six frames, and
  // its height wanders), and a badly calibrated clip loses only its first third of a second at
  // 30 frames/s. A fit held off a chrome ball at rest did (15 frames, on another random scene):
  // the frames reported from an adopted height are judged again at the clip's end
  // (RejudgeProvisionalFrames).
  static constexpr std::size_t kOnPathAdoptFrames = 10;
  // HeldOnPath: a model fit between kHeldFromPx and kOnPathFirstPx off the calibrated path is first
  // fitted again without the limb's shading profile, and taken where that lies within kHeldFromPx
  // of the path (OnPathWithoutLimb: a glossy limb mirrors the rods, and the profile fitted to it
  // held a ball at rest 1-2.8 px off the path); else it is fitted again held on it (a prior of σ
  // kHeldSigmaPx across it) and freely, both in the same windows, and the offset is kept only where
  // it lowers the rays' cost (Ceres' ½χ², over the fit's reduced χ²) by kHeldSignificance or more:
  // a χ² of 9, 3σ for one parameter. Where the rim shows no edge on one side (a pale print against
  // a grey wall, the near rail hiding the bottom) the outline slides across the path at no cost; a
  // striped spheroid at rest sat 1.4 px off it in every frame. From half kOnPathPx: correct fits
  // lie within 0.54 px of a calibrated path (above), and a fit nearer holds no more than it shows.
  // Not beyond kOnPathFirstPx: there a fit is reported only from an adopted height, and a fit
  // strayed 3–8 px off a released striped ball, held on the path, was reported 1 px off its body
  // instead of being left out.
  static constexpr double kHeldFromPx = 0.5, kHeldSigmaPx = 0.02, kHeldSignificance = 4.5;
  // Ceres iterations of both: from a fit that may not have settled (a narrow refit of a fit held
  // 2 px off moved it by 1.7 px).
  static constexpr int kHeldIterations = 3;
  // A body within this of where it was found anew, px, is still at rest there: an edge fit's
  // centre on a printed body scatters by a few tenths of a pixel, a rolling body leaves the
  // place within a few frames.
  static constexpr double kAtRestPx = 1.0;
  // Untrusted fast fits in a row after which the clip takes the model on every frame.
  static constexpr int kFastDistrust = 3;
  // Frames between background updates of the whole band: a still scene's background changes
  // only with the gain, which each frame's normalisation follows.
  static constexpr int kLearnEvery = 8;
  // A model fit whose smear measures the exposure: its inlier rays fit within 1.5 noise levels
  // and are at least this share of the rays (a ball's shadow, the rails' reflections and the
  // highlight leave 55-75 % of the rays inliers on rendered footage; the exposure is the median
  // over the frames).
  static constexpr double kExposureMinAgreement = 0.5;
  // The rolling shutter's readout, where measured: at the end of the clip the frames fitted at a
  // delay farther than this share of a whole frame's readout from the clip's are fitted again
  // (row_delay_settle.hpp).
  static constexpr double kReadoutNear = 0.2;
  // The readout's systematic uncertainty, s, added in quadrature to the frames' standard error:
  // the smear model errs most at the smear's ends, where the shear shows, and that leaks into the
  // delay the same way on every frame (on global-shutter footage the measured readout lies
  // within 2.5 u of 0 with it).
  static constexpr double kReadoutSystematic = 0.003;
  // The readout is measured on up to kReadoutFrames frames and used from kReadoutMinFrames on:
  // a median of five resists one bad frame, and more frames add little once the systematic
  // part dominates.
  static constexpr std::size_t kReadoutFrames = 15, kReadoutMinFrames = 5;
  // The opening (tracker_state.hpp): frames in a row found and confirmed by the background before
  // the body counts as tracked (one frame can be a coincidence of texture; five in a row at a
  // ball's speeds are its motion); the memory its frames may take (a 720p clip's band keeps about
  // 300 frames, five seconds at 60 fps, of a body at rest).
  static constexpr int kOpeningAnchorFrames = 5;
  static constexpr std::size_t kOpeningBytes = 256u << 20;
  // SilhouetteOf: a sample inside the outline is the body's when it differs from the
  // background by this many noise levels (and at least kSilhouetteMinContrast, linear light) in a
  // channel; the inside is a body's when this share of its samples are (a mirror ball shows the
  // table near its limb, a print may match the cloth in places: most of the inside still differs);
  // the ring just outside is the background's where this share of its samples match it (the
  // shadow and the rails' reflections cost some); and the background must be known under this
  // share of each ring's samples to decide at all.
  static constexpr double kSilhouetteNoiseLevels = 5, kSilhouetteMinContrast = 0.02;
  static constexpr double kSilhouetteMinBodyShare = 0.6, kSilhouetteMinBackgroundShare = 0.75;
  static constexpr double kSilhouetteMinKnownShare = 0.7;
  // Backwards through the opening: frames in a row the body may be missed (the near rail, a
  // highlight) before the search stops.
  static constexpr int kOpeningMaxMisses = 3;
};

}  // namespace uphill::internal
