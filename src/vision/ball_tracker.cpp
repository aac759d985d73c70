#include "vision/ball_tracker.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <opencv2/imgproc.hpp>

#include "model/input_error.hpp"
#include "internal/background_model.hpp"
#include "internal/edge_fit.hpp"
#include "internal/motion_prediction.hpp"
#include "internal/outline_fit.hpp"
#include "internal/rejected_windows.hpp"
#include "internal/row_delay_settle.hpp"

namespace uphill {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using internal::FitOutcome;
using internal::FitRequest;

constexpr double kNarrowHalfWidthPx = 1.5;  // second pass, around the first fit
// Ceres iterations of the narrow pass after a coarse search (outline_fit.hpp,
// FitRequest::iterations): the ray-traced clips measure as with 3 (spheroid-band 0.251 px against
// 0.248, fast-360-30 0.238 against 0.237) at 10 % less of the tracker's time.
constexpr int kNarrowIterations = 2;
// Ceres iterations of a pass started at a fit of the same frame or at a checked prediction,
// within half a pixel or so, where Kaufman's step leaves about a quarter of the offset: the
// narrow pass where the model measured the frame before (MeasureNear), both passes of a refit,
// and the refit of a frame at the settled row delay. On the ray-traced clips one iteration there
// instead of two measures fast-360-30 at 0.233 px (0.236), spheroid-band 0.258 (0.253) and
// rolling-shutter 0.168 (0.159), in 12 % less of fast-360-30's instructions; with the coarse
// pass's repeat below, 0.228, 0.250 and 0.159 px before both (docs/track.md).
constexpr int kStartedNearIterations = 1;
constexpr int kHistoryGap = 5;              // frames without the body after which we predict no more
constexpr size_t kHistory = 6;              // samples the prediction is fitted to
constexpr double kSceneChangeFactor = 4;    // scene residual jump (times its usual level, plus 0.01)
// The usual level is never taken below this: H.264 copies static blocks exactly, so the first
// frames of a clip can show no residual at all, and the first key frame would look like a change.
constexpr double kUsualResidualFloor = 0.005;
constexpr int kConfirmFrames = 3;           // frames that confirm a scene or exposure change
// The fast path (internal/edge_fit.hpp) and when it is trusted.
constexpr int kEdgePoints = 96;             // edge searches per frame
// Predicted smear over the exposure, in radii, up to which the fast path is tried (its own checks
// deciding), with the exposure known and with it guessed (a 180° shutter). On the ray-traced lab
// clips 0.375 measures as well as 0.25 (baseline 0.067 px against 0.076) at half the tracker's
// time, and the synthetic 360° fast clip the same (0.055 px).
constexpr double kFastMaxBlur = 0.375, kFastMaxBlurGuessed = 0.5;
constexpr double kFastMinContrast = 20;     // grey levels across the outline
constexpr double kFastMaxRmsPx = 0.3;       // RMS of the edge points about the fitted outline
constexpr double kFastMinAgreement = 0.85;  // share of the searched rays that are inliers
constexpr double kFastMaxDisagreementPx = 0.5;  // edge fit against the model, at acquisition
constexpr int kFastDistrust = 3;            // untrusted fast fits in a row: the clip needs the model
constexpr int kLearnEvery = 8;              // frames between background updates of the whole band
// A model fit whose smear measures the exposure: its inlier rays fit within 1.5 noise levels and
// are at least this share of the rays (a half: on ray-traced footage a ball's shadow, the rails'
// reflections and the highlight leave 55-75 % of the rays inliers, and the exposure is the
// median over the frames).
constexpr double kExposureMinAgreement = 0.5;
// The rolling shutter's readout, where measured: on up to kReadoutFrames frames, used from
// kReadoutMinFrames; at the end of the clip the frames fitted at a delay farther than this share
// of a whole frame's readout from the clip's are fitted again (row_delay_settle.hpp).
constexpr double kReadoutNear = 0.2;
// The readout's systematic uncertainty, s, added in quadrature to the frames' standard error: the
// smear model errs most at the smear's ends, where the shear shows, and that leaks into the
// delay the same way on every frame. Calibrated on the ray-traced matrix (docs/track.md): on the
// four global-shutter fast clips `--readout auto` measured 0.2 to 9.8 ms of the true 0 with
// standard errors of 0.7 to 3.4 ms (up to 10 of them off); with 3 ms more each lies within 2.5 u.
constexpr double kReadoutSystematic = 0.003;
constexpr size_t kReadoutFrames = 15, kReadoutMinFrames = 5;

struct Sample {
  double t, x, z;  // s (clip time of the reported centre), m
  // The frame's time and the centre's row: under a rolling shutter t is frame_t + row·δ, δ the
  // rows' delay as known now (the samples are re-timed whenever it changes).
  double frame_t = 0, row = 0;
};

}  // namespace

struct BallTracker::Impl {
  // Whether a search follows the body (a prediction or a frame's own fit to start from) or
  // looks for it anew.
  enum class Search { kTracking, kAcquiring };

  Scene scene;
  TrackerOptions options;
  internal::OutlineGeometry geometry;
  cv::Mat occluder;                                 // CV_8U: the near rail's band
  std::unique_ptr<internal::BackgroundModel> background;
  std::unique_ptr<internal::BodyShading> shading;   // learnt from the first frames at rest
  double light_inverse_distance = 0;                // 1/m: its lamp's, in the last model fit
  std::deque<std::pair<long, Sample>> history;      // last found (frame, sample)
  long frame_index = -1;
  double x_lo = 0, x_hi = 0;                        // searchable part of the path
  double lens_reach = 0;                            // LensModelReach of the camera
  double noise = 0.01;                              // residual RMS of a sample, linear units
  std::deque<double> noises;                        // of the last accepted frames
  double row_delay = 0;                             // s per row
  std::vector<double> exposures;                    // per-frame measurements |D|/|V|
  std::vector<double> row_delays;                   // per-frame measurements of the row delay, s
  // The frames that measured the row delay: a window of each, its last fit's request (made at
  // request.row_delay) and that fit's estimate; the far ones fitted again at the end of the clip
  // (SettleReadout).
  struct ReadoutFrame {
    cv::Mat window;
    cv::Point origin;
    double gain;
    FitRequest request;
    internal::FrameDelay estimate;
  };
  std::vector<ReadoutFrame> readout_frames;
  std::optional<double> row_delay_u;                // s per row, once settled
  int row_delay_frames = 0;                         // the frames it was settled on
  std::vector<double> scene_residuals;              // recent steady levels
  int scene_suspect = 0;
  long scene_suspect_from = -1;
  std::optional<long> scene_changed_at;
  std::deque<std::pair<long, double>> gains;        // (frame, gain)
  // Every accepted frame's centre (revised ones included), for the velocity at a past frame.
  std::map<long, Sample> samples;
  // Frames measured before the background under the body or its motion was known: a window of
  // the frame each, fitted again once both are (FitAgain), their revised observations handed out
  // by TakeRevisions.
  struct Pending {
    long frame;
    double t, gain;
    cv::Mat window;
    cv::Point origin;
    BallObservation observed;
    Vector2d centre;  // fitted, at the reference time
    bool edge_fallback = false;  // observed by the edge fit: keep it unless the background becomes known
  };
  std::deque<Pending> pending;
  size_t pending_bytes = 0;
  std::vector<std::pair<long, BallObservation>> revisions;
  std::vector<long> exposure_changes;
  // Fast path: the edge fit; whether this clip needs the full model on every frame (its grey
  // contrast is low, its body patterned, or the edge fit keeps failing), and why.
  std::unique_ptr<internal::EdgeFit> edges;
  bool needs_model = false;
  int distrusted = 0;
  long confident_model_frame = -1;  // the last frame the model measured, its background known
  long learnt_near_at = -1;         // the last frame whose background the model's path learnt
  // A body found anew where the model could not check it against the background (rays whose
  // background was never seen: the first frames of a clip) counts once the next frames find it
  // again near it; found in that frame alone it was the table's texture (wood grain between the
  // rails), not a body, and it is withdrawn (a revision that says not found).
  struct Unconfirmed {
    long frame;
    bool needs_model_before;
  };
  std::optional<Unconfirmed> unconfirmed;
  // The whole-path search's candidates fitted and rejected since the body was last found, with
  // their pixels (see rejected_windows.hpp).
  internal::RejectedWindows rejected;

  Impl(const Scene& sc, const TrackerOptions& o) : scene(sc), options(o) {}

  double Exposure() const {
    if (options.exposure) return *options.exposure;
    if (exposures.size() >= 3) {
      std::vector<double> e = exposures;
      std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
      return e[e.size() / 2];
    }
    return 0.5 / options.fps;  // a 180° shutter, the usual default of video cameras
  }

  // Whether this frame's fit measures the row delay (TrackerOptions::measure_readout): until
  // kReadoutFrames have, where a whole frame's readout would shear the body by over a pixel.
  bool MeasuresReadout(const Vector2d& centre, const Vector2d& velocity) const {
    if (!options.measure_readout || row_delays.size() >= kReadoutFrames || velocity.isZero()) return false;
    const double px_per_s = velocity.norm() / MetresPerPx(centre.x(), centre.y());
    return px_per_s * 2 * RadiusPx(centre.x(), centre.y()) * FrameRowDelay() > 1;
  }

  // A frame's measured row delay; the median of all so far is used from kReadoutMinFrames on.
  // False for a fit that did not see the shear (a delay far outside one frame time's).
  bool MeasuredRowDelay(double delay) {
    if (!SeesShear(delay)) return false;
    row_delays.push_back(delay);
    if (row_delays.size() < kReadoutMinFrames) return true;
    std::vector<double> d = row_delays;
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    SetRowDelay(std::clamp(d[d.size() / 2], 0.0, 0.999 * FrameRowDelay()));
    return true;
  }
  // A centre reported in the frame of time t, at the time of its row with the rows' delay as now
  // known (its time_offset, unless the delay changed since it was measured).
  Sample SampleOf(double t, const BallObservation& o) const { return Sample{t + o.v * row_delay, o.x, o.z, t, o.v}; }
  // The rows' delay from here on, and the times of the centres measured so far with it: those
  // measured before it was known (at a global shutter's 0, the first five) lie several pixels
  // off the motion of those after, and the prediction from both would miss by as much.
  void SetRowDelay(double delay) {
    row_delay = delay;
    for (auto& [frame, s] : samples) s.t = s.frame_t + s.row * row_delay;
    for (auto& [frame, s] : history) s.t = s.frame_t + s.row * row_delay;
  }
  bool SeesShear(double delay) const { return delay > -0.5 * FrameRowDelay() && delay < 1.5 * FrameRowDelay(); }
  // The row delay of a readout lasting the whole frame time, s per row: the most a camera has.
  double FrameRowDelay() const { return 1 / options.fps / geometry.cal.camera.height; }

  double RadiusPx(double x, double z) const {
    const Vector3d c(x, 0, z);
    return geometry.a * geometry.cal.camera.fx / (c - geometry.eye).norm();
  }
  double MetresPerPx(double x, double z) const { return 1.0 / (geometry.cal.camera.fx / (Vector3d(x, 0, z) - geometry.eye).norm()); }

  // The motion through the history (motion_prediction.hpp), while the body may still be predicted
  // from it.
  std::optional<internal::MotionFit> Motion(long f) const {
    if (history.empty() || f - history.back().first > kHistoryGap) return std::nullopt;
    std::vector<internal::TimedCentre> timed;
    for (const auto& [frame, s] : history) timed.push_back({s.t, Vector2d(s.x, s.z)});
    return internal::MotionFit::Through(timed);
  }

  // The body's region (smeared silhouette, a radius around it, and its shadow below it), px.
  cv::Rect BodyRegion(const Vector2d& centre, const Vector2d& smear) const {
    const Vector2d a = geometry.Project(centre.x() - 0.5 * smear.x(), centre.y() - 0.5 * smear.y());
    const Vector2d b = geometry.Project(centre.x() + 0.5 * smear.x(), centre.y() + 0.5 * smear.y());
    const double r = RadiusPx(centre.x(), centre.y()) * std::max(1.0, 1.0 / geometry.s);
    const double pad = 2 * r + 4;
    const int x0 = static_cast<int>(std::floor(std::min(a.x(), b.x()) - pad));
    const int y0 = static_cast<int>(std::floor(std::min(a.y(), b.y()) - pad));
    const int x1 = static_cast<int>(std::ceil(std::max(a.x(), b.x()) + pad));
    const int y1 = static_cast<int>(std::ceil(std::max(a.y(), b.y()) + pad + r));
    return cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & cv::Rect(0, 0, occluder.cols, occluder.rows);
  }

  // The path's direction at x (unit, (x, z)).
  Vector2d PathTangent(double x) const {
    const double slope = scene.At(std::clamp(x, x_lo, x_hi)).dzdx;
    return Vector2d(1, slope).normalized();
  }

  // `acceleration` bends the smear over the exposure (smeared_outline.hpp); zero when unknown.
  FitRequest Request(const Vector2d& centre, const Vector2d& velocity, bool moving_known, double half_width,
                     const Vector2d& acceleration = Vector2d::Zero()) const {
    FitRequest q;
    q.centre = centre;
    q.velocity = velocity;
    q.rays = options.rays;
    q.noise = noise;
    q.light_inverse_distance = light_inverse_distance;
    q.half_width_px = half_width;
    q.row_delay = row_delay;
    q.estimate_row_delay = MeasuresReadout(centre, velocity);
    q.reference_row = geometry.Project(centre.x(), centre.y()).y();
    const double m_per_px = MetresPerPx(centre.x(), centre.y());
    if (moving_known) {
      q.smear = velocity * Exposure();
      q.bend = 0.5 * acceleration * Exposure() * Exposure();
      // How well the exposure is known: given, measured on enough frames, or the guess.
      const double relative = options.exposure ? 0.1 : exposures.size() >= 5 ? 0.15 : 0.5;
      q.smear_sigma = relative * q.smear.norm() + 0.5 * m_per_px;
    } else {
      // Nothing known of the motion yet (a body found for the first time is taken at rest; the
      // frames after it give its speed).
      q.smear = Vector2d::Zero();
      q.smear_sigma = 0.5 * m_per_px;
    }
    if (q.smear.norm() < 0.25 * m_per_px) q.smear = PathTangent(centre.x()) * 0.25 * m_per_px;
    return q;
  }

  // A fit is a body when enough rays agree with it, the body stands out of the background by
  // several noise levels, and its inlier rays fit within a few noise levels. `agreement`: the
  // share of the fitted rays that must be inliers (less near the prediction, where a painted
  // body's band or the rails may cost rays, than for a body found anew).
  bool Accept(const FitOutcome& f, double agreement) const {
    return f.ok && f.inliers >= std::max(10.0, 0.25 * options.rays) && f.inliers >= agreement * f.rays_fitted &&
           f.contrast >= options.min_contrast && f.contrast >= 6 * noise && f.misfit < 3;
  }

  // Two passes: around the guess with the given half width, then narrow around the first fit
  // (with `narrow_iterations`; q.iterations caps the first passes).
  FitOutcome Measure(const internal::FrameView& view, FitRequest q, Search search = Search::kTracking,
                     int narrow_iterations = kNarrowIterations) {
    // Every pass with the edge shift held: far from the edges it would rather shrink the outline
    // onto an inner edge than move it, and near them it moves the centre across the motion
    // (MeasureNear). The first pass again from where it went while it moves more
    // than a pixel and its last iteration still moved it by a pixel or more (the windows follow
    // a solve that had not settled; one that had moves by less than 0.25 px when repeated on the
    // fast ray-traced clips; a refit's single iteration has moved the whole way, so there the
    // move alone decides), then a narrow pass around the result. A body found anew is fitted again
    // whenever it moved more than a pixel: the repeat starts the smear afresh from its prior,
    // where the first fit, far from the edges, may have taken a spurious one (on the phone clip
    // the first frame then failed the inlier share a new body needs).
    q.fit_edge_shift = false;
    q.fit_light = false;
    // The row delay is read from the last pass only.
    const bool estimate_row_delay = q.estimate_row_delay;
    q.estimate_row_delay = false;
    FitOutcome first;
    for (int pass = 0; pass < 3; ++pass) {
      first = internal::FitOutline(geometry, view, *background, q);
      if (!first.ok) return first;
      const Vector2d moved = geometry.Project(first.p[internal::kCentreX], first.p[internal::kCentreZ]) -
                             geometry.Project(q.centre.x(), q.centre.y());
      q.centre = Vector2d(first.p[internal::kCentreX], first.p[internal::kCentreZ]);
      q.reference_row = geometry.Project(q.centre.x(), q.centre.y()).y();
      if (moved.norm() < 1.0 || (search == Search::kTracking && first.last_step_px < 1.0)) break;
      q.half_width_px = std::max(kNarrowHalfWidthPx + 1, 0.5 * q.half_width_px);
    }
    q.smear = Vector2d(first.p[internal::kSmearX], first.p[internal::kSmearZ]);
    q.estimate_row_delay = estimate_row_delay;
    q.fit_light = true;
    q.half_width_px = kNarrowHalfWidthPx;
    q.iterations = narrow_iterations;
    FitOutcome second = internal::FitOutline(geometry, view, *background, q);
    return second.ok ? second : first;
  }

  // One narrow pass, where the prediction is good (the model measured the previous frame, its
  // background known): one Ceres solve instead of two or more. Measure() when the fit moves more
  // than half a pixel from the prediction or fails. The edge shift is held as in Measure(), so
  // that both fit the same parameters: freed here alone, it moved the centre across the motion
  // by up to 0.3 px on the fast clips' frames this pass measures (fast-180-30 0.216 px RMS
  // against 0.190 held, fast-360-60 0.170 against 0.161, rolling-shutter 0.192 against 0.165
  // with the prediction at the row's own time in both; fast-360-30 alone the other way, 0.241
  // against 0.261; the renderer's camera). Freed in both it was worse on all four.
  FitOutcome MeasureNear(const internal::FrameView& view, FitRequest q) {
    const FitRequest wide = q;
    q.half_width_px = kNarrowHalfWidthPx + 1;
    q.fit_edge_shift = false;
    q.iterations = kStartedNearIterations;
    const FitOutcome one = internal::FitOutline(geometry, view, *background, q);
    if (one.ok && (geometry.Project(one.p[internal::kCentreX], one.p[internal::kCentreZ]) -
                   geometry.Project(q.centre.x(), q.centre.y())).norm() < 0.5)
      return one;
    return Measure(view, wide);
  }

  // Whether the lens model maps the camera-frame point where it is (LensModelReach).
  bool WithinLens(const Vector3d& pc) const { return pc.z() > 0 && pc.head<2>().norm() < lens_reach * pc.z(); }

  // Candidates along the path between x0 and x1, best first: the predicted outline's inside
  // against its outside (against the background where it is known).
  std::vector<Vector2d> Candidates(const cv::Mat& frame, double gain, double x0, double x1) const {
    x0 = std::max(x0, x_lo);
    x1 = std::min(x1, x_hi);
    if (!(x1 > x0)) return {};
    const int n = 32;
    // Candidates a quarter radius apart in the image.
    const Vector2d p0 = geometry.Project(x0, scene.At(x0).z), p1 = geometry.Project(x1, scene.At(x1).z);
    const double r_mid = RadiusPx(0.5 * (x0 + x1), scene.At(0.5 * (x0 + x1)).z);
    const int count = std::clamp(static_cast<int>((p1 - p0).norm() / std::max(1.0, 0.25 * r_mid)) + 1, 8, 2000);
    std::vector<std::pair<double, double>> scored;  // (score, x)
    std::vector<cv::Vec3f> inside(n), outside(n);
    for (int i = 0; i < count; ++i) {
      const double xc = x0 + (x1 - x0) * (i + 0.5) / count;
      const double zc = scene.At(xc).z;
      if (!WithinLens(geometry.cal.pose.rotation * Vector3d(xc, 0, zc) + geometry.cal.pose.translation)) continue;
      std::vector<Vector3d> pts = geometry.OutlinePoints(xc, zc, n);
      pts.emplace_back(xc, 0, zc);
      const std::vector<Vector2d> image = ProjectApparatusPoints(geometry.cal.camera, geometry.cal.pose, pts);
      const Vector2d q = image[n];
      int used = 0;
      std::vector<double> bg_in, bg_out;
      for (int k = 0; k < n; ++k) {
        const Vector2d dir = (image[k] - q).normalized();
        const double r = (image[k] - q).norm();
        const Vector2d pin = image[k] - 0.4 * r * dir, pout = image[k] + 3.0 * dir;
        bool ok = std::min({pin.x(), pin.y(), pout.x(), pout.y()}) >= 1 && std::max(pin.x(), pout.x()) < frame.cols - 2 &&
                  std::max(pin.y(), pout.y()) < frame.rows - 2;
        ok = ok && !occluder.at<std::uint8_t>(static_cast<int>(pout.y() + 0.5), static_cast<int>(pout.x() + 0.5));
        if (!ok) continue;
        inside[used] = internal::SampleLinear(frame, background->table(), pin.x(), pin.y());
        outside[used] = internal::SampleLinear(frame, background->table(), pout.x(), pout.y());
        if (background->Known(pin.x(), pin.y()) && background->Known(pout.x(), pout.y())) {
          bg_in.push_back(cv::norm(inside[used] - background->At(pin.x(), pin.y()) * gain));
          bg_out.push_back(cv::norm(outside[used] - background->At(pout.x(), pout.y()) * gain));
        }
        ++used;
      }
      if (used < n / 2) continue;
      double score;
      if (static_cast<int>(bg_in.size()) >= used * 3 / 4) {
        // Inside differs from the background, outside does not.
        std::nth_element(bg_in.begin(), bg_in.begin() + bg_in.size() / 2, bg_in.end());
        std::nth_element(bg_out.begin(), bg_out.begin() + bg_out.size() / 2, bg_out.end());
        score = bg_in[bg_in.size() / 2] - bg_out[bg_out.size() / 2];
      } else {
        // The inside's median colour against each outside sample: a body of one colour on any
        // surroundings gives a consistent step.
        cv::Vec3f median_in;
        std::vector<float> channel(used);
        for (int c = 0; c < 3; ++c) {
          for (int k = 0; k < used; ++k) channel[k] = inside[k][c];
          std::nth_element(channel.begin(), channel.begin() + used / 2, channel.end());
          median_in[c] = channel[used / 2];
        }
        std::vector<double> steps(used);
        for (int k = 0; k < used; ++k) steps[k] = cv::norm(median_in - outside[k]);
        std::nth_element(steps.begin(), steps.begin() + used / 4, steps.end());
        score = steps[used / 4];  // the lower quartile: the step must hold nearly all round
      }
      scored.emplace_back(score, xc);
    }
    std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<Vector2d> out;
    for (const auto& [score, xc] : scored) {
      if (score < options.min_contrast || out.size() >= 3) break;
      // Distinct candidates: at least a radius apart.
      const Vector2d p = geometry.Project(xc, scene.At(xc).z);
      bool near = false;
      for (const Vector2d& o : out) near = near || (geometry.Project(o.x(), o.y()) - p).norm() < RadiusPx(xc, scene.At(xc).z);
      if (!near) out.emplace_back(xc, scene.At(xc).z);
    }
    return out;
  }

  // Quality in [0, 1]: the share of the visible outline's rays that agree with the fit, lowered
  // when those fit worse than the pixel noise allows and when the body stands out of the
  // background by less than 20 noise levels.
  double Quality(const FitOutcome& f) const {
    const double fraction = std::min(1.0, static_cast<double>(f.inliers) / std::max(1, f.rays_tried));
    const double excess = std::max(0.0, f.misfit - 1.5);
    const double snr = f.contrast / std::max(noise, 1e-6);
    return fraction * std::exp(-0.5 * excess * excess) * std::min(1.0, snr / 20);
  }

  // The centre (x, z), its pixel and the outline's mean radius about it.
  void Place(const Vector2d& centre, BallObservation* o) const {
    o->x = centre.x();
    o->z = centre.y();
    const Vector2d uv = geometry.Project(o->x, o->z);
    o->u = uv.x();
    o->v = uv.y();
    double sum = 0;
    for (const Vector2d& p : ProjectApparatusPoints(geometry.cal.camera, geometry.cal.pose, geometry.OutlinePoints(o->x, o->z, 32)))
      sum += (p - uv).norm();
    o->radius_px = sum / 32;
  }

  BallObservation Observe(const FitOutcome& f, const FitRequest& q) {
    BallObservation o;
    o.found = true;
    const Vector2d c_ref(f.p[internal::kCentreX], f.p[internal::kCentreZ]);
    // The reference time is the mid-exposure of row q.reference_row; report at the row where the
    // centre lies (fixed point: the row moves by |dv/dt|·delay ≪ 1 row per iteration).
    Vector2d c = c_ref;
    double offset = 0;
    if (row_delay > 0) {
      for (int it = 0; it < 3; ++it) {
        const double row = geometry.Project(c.x(), c.y()).y();
        offset = row * row_delay;
        c = c_ref + q.velocity * ((row - q.reference_row) * row_delay);
      }
    }
    Place(c, &o);
    o.time_offset = offset;
    const Vector2d smear(f.p[internal::kSmearX], f.p[internal::kSmearZ]);
    o.smear_px = (geometry.Project(c_ref.x() + 0.5 * smear.x(), c_ref.y() + 0.5 * smear.y()) -
                  geometry.Project(c_ref.x() - 0.5 * smear.x(), c_ref.y() - 0.5 * smear.y()))
                     .norm();
    o.rays = f.rays_fitted;
    o.inliers = f.inliers;
    o.misfit = f.misfit;
    o.quality = Quality(f);
    o.full_model = true;
    return o;
  }

  // The fast path's fit is trusted when it saw the outline nearly all round, in grey-level
  // contrast well above the noise, and its edge points lie on the fitted outline.
  bool Trusted(const internal::EdgeFitOutcome& e) const {
    return e.ok && e.inliers >= 0.35 * kEdgePoints && e.inliers >= kFastMinAgreement * e.attempted &&
           e.contrast >= kFastMinContrast && e.rms_px <= kFastMaxRmsPx;
  }

  BallObservation ObserveEdges(const internal::EdgeFitOutcome& e) const {
    BallObservation o;
    o.found = true;
    Place(Vector2d(e.x, e.z), &o);
    o.rays = e.edge_points;
    o.inliers = e.inliers;
    o.misfit = e.rms_px / 0.1;  // in units of a good edge fit's scatter
    const double fraction = std::min(1.0, static_cast<double>(e.inliers) / std::max(1, e.attempted));
    o.quality = fraction * std::exp(-e.rms_px * e.rms_px / (2 * 0.25));
    o.full_model = false;
    return o;
  }

  // A frame where the body rests (found near a prediction that barely moves) is a sharp view of
  // its shading.
  void LearnShading(const cv::Mat& frame, const BallObservation& o, const Vector2d& velocity) {
    if (shading->ready() || history.size() < 3 || !o.found) return;
    if (velocity.norm() / options.fps / MetresPerPx(o.x, o.z) > 0.05) return;
    shading->Learn(frame, background->table(), geometry, o.x, o.z);
  }

  void Remember(long f, double t, const BallObservation& o) {
    // Found again from the unconfirmed frame's track (still in the history): confirmed.
    if (unconfirmed && f > unconfirmed->frame && !history.empty() && history.front().first <= unconfirmed->frame)
      unconfirmed.reset();
    samples[f] = SampleOf(t, o);
    history.emplace_back(f, samples[f]);
    if (history.size() > kHistory) history.pop_front();
  }

  // The velocity and acceleration at time t of frame f from the accepted centres of the frames
  // around it (a parabola in time through up to four on each side); false with fewer than two on
  // each side.
  bool VelocityAround(long f, double t, Vector2d* velocity, Vector2d* acceleration) const {
    std::vector<internal::TimedCentre> near;
    int before = 0, after = 0;
    for (auto it = samples.lower_bound(f - 4); it != samples.end() && it->first <= f + 4; ++it) {
      if (it->first == f) continue;
      near.push_back({it->second.t, Vector2d(it->second.x, it->second.z)});
      (it->first < f ? before : after)++;
    }
    if (before < 2 || after < 2) return false;
    const auto fit = internal::MotionFit::Through(near);
    if (!fit) return false;
    const internal::MotionState state = fit->At(t);
    *velocity = state.velocity;
    *acceleration = state.acceleration;
    return true;
  }

  // Whether the background is known everywhere around the body centred at `centre` (its region,
  // on a 12 × 12 lattice of the band's pixels).
  bool BackgroundKnownAround(const Vector2d& centre) const {
    const Vector2d q = geometry.Project(centre.x(), centre.y());
    const double r = RadiusPx(centre.x(), centre.y()) * std::max(1.0, 1.0 / geometry.s) + 8;
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        const double x = q.x() + r * (2.0 * i / 11 - 1), y = q.y() + r * (2.0 * j / 11 - 1);
        if (x < 1 || y < 1 || x > occluder.cols - 3 || y > occluder.rows - 3) continue;
        if (background->InBand(x, y) && !background->Known(x, y)) return false;
      }
    return true;
  }

  // Keeps a window of the frame for a refit when the fit lacked the background or the motion.
  void KeepForRefit(long f, double t, const cv::Mat& frame, double gain, const FitOutcome& fit,
                    const BallObservation& o, bool motion_known, bool edge_fallback) {
    if (fit.rays_without_background == 0 && motion_known) return;
    const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
    const Vector2d smear(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]);
    const cv::Rect box = KeptWindow(c, smear * 2, frame);
    if (box.empty()) return;
    constexpr size_t kPendingBytes = 256u << 20;  // enough for minutes of a body at rest
    const size_t bytes = box.area() * 3u;
    if (pending_bytes + bytes > kPendingBytes) return;
    pending.push_back({f, t, gain, frame(box).clone(), box.tl(), o, c, edge_fallback});
    pending_bytes += bytes;
  }

  // The part of a frame kept for a later fit: the body's region, 24 px more each side (a fit
  // started there may move by that much).
  cv::Rect KeptWindow(const Vector2d& centre, const Vector2d& smear, const cv::Mat& frame) const {
    const cv::Rect box = BodyRegion(centre, smear);
    return cv::Rect(box.x - 24, box.y - 24, box.width + 48, box.height + 48) & cv::Rect(0, 0, frame.cols, frame.rows);
  }

  // A frame that measured the row delay, for SettleReadout: the window its smear covers, the
  // request of a narrow pass from its fit, and its estimate. The smear's prior stays the motion's
  // prediction: one centred on the smear fitted at this frame's delay would hold part of the
  // shear that delay got wrong.
  void KeepReadoutFrame(const cv::Mat& frame, double gain, const FitOutcome& fit, FitRequest q) {
    q.centre = Vector2d(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
    q.reference_row = geometry.Project(q.centre.x(), q.centre.y()).y();
    q.half_width_px = kNarrowHalfWidthPx;
    // The edge shift free here alone (this refit places no centre): held, fast-360-30's readout
    // with --readout auto came out 11.4 ± 4.0 ms of the true 0 (2.8 u) against 10.7 ± 4.6 free.
    q.fit_edge_shift = q.fit_light = true;
    q.iterations = kStartedNearIterations;
    q.light_inverse_distance = fit.light_inverse_distance;
    q.estimate_row_delay = true;
    const cv::Rect box = KeptWindow(q.centre, 2 * Vector2d(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]), frame);
    if (!box.empty())
      readout_frames.push_back({frame(box).clone(), box.tl(), gain, q, {fit.row_delay, fit.row_delay_sigma}});
  }

  // The clip's row delay, settled on the frames that measured it (row_delay_settle.hpp), and its
  // standard uncertainty; the running median of their estimates is kept when it cannot be.
  void SettleReadout() {
    if (readout_frames.size() < kReadoutMinFrames) return;
    std::vector<internal::FrameFit> fits;
    std::vector<double> fitted_at;
    for (const ReadoutFrame& k : readout_frames) fits.push_back(k.estimate), fitted_at.push_back(k.request.row_delay);
    auto refit = [&](size_t i, double q) -> internal::FrameFit {
      const ReadoutFrame& k = readout_frames[i];
      FitRequest r = k.request;
      r.row_delay = q;
      const FitOutcome fit = internal::FitOutline(geometry, {k.window, k.origin, k.gain}, *background, r);
      if (fit.ok && fit.row_delay_sigma > 0 && SeesShear(fit.row_delay))
        return internal::FrameDelay{fit.row_delay, fit.row_delay_sigma};
      return std::nullopt;
    };
    const double most = 0.999 * FrameRowDelay();
    if (const auto settled = internal::SettleRowDelay(fits, fitted_at, kReadoutNear * FrameRowDelay(), most,
                                                      kReadoutMinFrames, refit)) {
      SetRowDelay(settled->delay);
      row_delay_u = std::hypot(settled->u, kReadoutSystematic / geometry.cal.camera.height);
      row_delay_frames = settled->frames;
    }
  }

  // Fits kept frames again whose background and motion are now known (all of them when `all`,
  // with whatever is known by then).
  void FitAgain(bool all) {
    for (auto it = pending.begin(); it != pending.end();) {
      Vector2d velocity, acceleration;
      const bool motion = VelocityAround(it->frame, it->t, &velocity, &acceleration);
      const bool background_known = BackgroundKnownAround(it->centre);
      const bool ready = (motion || all) && (all || background_known);
      if (!ready) {
        ++it;
        continue;
      }
      // Where the background under the body was never seen the model's per-ray background is
      // less sure than the edge fit that stood in for it.
      if (it->edge_fallback && !background_known) {
        pending_bytes -= it->window.total() * it->window.elemSize();
        it = pending.erase(it);
        continue;
      }
      if (!motion) velocity = acceleration = Vector2d::Zero();
      FitRequest q = Request(it->centre, velocity, motion, kNarrowHalfWidthPx + 1.5, acceleration);
      // Started at the frame's own fit, within a pixel or so.
      q.iterations = kStartedNearIterations;
      q.estimate_row_delay = false;  // measured when the frame was first fitted
      const FitOutcome fit = Measure({it->window, it->origin, it->gain}, q, Search::kTracking, kStartedNearIterations);
      if (Accept(fit, 0.45)) {
        BallObservation o = Observe(fit, q);
        const double moved = std::hypot(o.u - it->observed.u, o.v - it->observed.v);
        if (moved < 0.5 * RadiusPx(o.x, o.z)) {
          revisions.emplace_back(it->frame, o);
          samples[it->frame] = SampleOf(it->t, o);
        }
      }
      pending_bytes -= it->window.total() * it->window.elemSize();
      it = pending.erase(it);
    }
  }

  void Withdraw() {
    const long k = unconfirmed->frame;
    revisions.emplace_back(k, BallObservation{});
    samples.erase(k);
    for (auto it = pending.begin(); it != pending.end();) {
      if (it->frame != k) {
        ++it;
        continue;
      }
      pending_bytes -= it->window.total() * it->window.elemSize();
      it = pending.erase(it);
    }
    std::erase_if(history, [k](const auto& h) { return h.first == k; });
    needs_model = unconfirmed->needs_model_before;
    unconfirmed.reset();
  }

  // Scene residual and gain bookkeeping (SceneChangedAt, ExposureChanges).
  void WatchScene(long f) {
    const double residual = background->SceneResidual();
    if (residual >= 0) {
      double usual = -1;
      if (scene_residuals.size() >= 5) {
        std::vector<double> r = scene_residuals;
        std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
        usual = std::max(r[r.size() / 2], kUsualResidualFloor);
      }
      if (usual > 0 && residual > kSceneChangeFactor * usual + 0.01) {
        if (scene_suspect++ == 0) scene_suspect_from = f;
        if (scene_suspect >= kConfirmFrames && !scene_changed_at) scene_changed_at = scene_suspect_from;
      } else {
        scene_suspect = 0;
        scene_residuals.push_back(residual);
        if (scene_residuals.size() > 30) scene_residuals.erase(scene_residuals.begin());
      }
    }
    gains.emplace_back(f, background->Gain());
    if (gains.size() > kConfirmFrames + 2) gains.pop_front();
    // A step between frames k−1 and k that the next frames keep.
    if (gains.size() == kConfirmFrames + 2) {
      const double before = gains[0].second, step_from = gains[1].second;
      bool holds = std::abs(std::log(step_from / before)) > std::log(1.25);
      for (size_t k = 2; k < gains.size() && holds; ++k) holds = std::abs(std::log(gains[k].second / step_from)) < std::log(1.1);
      if (holds && (exposure_changes.empty() || exposure_changes.back() < gains[1].first - kConfirmFrames))
        exposure_changes.push_back(gains[1].first);
    }
  }
};

BallTracker::BallTracker(const Scene& scene, const SceneCalibration& calibration, const TrackerOptions& options)
    : impl_(std::make_unique<Impl>(scene, options)) {
  ValidateIntrinsics(calibration.camera, "camera");
  const Body& body = scene.body();
  if (body.kind == BodyKind::kDoubleCone)
    throw InputError("--body", "tracking supports a sphere or a spheroid, not a double cone");
  if (options.rays < 16 || options.rays > 1024) throw InputError("rays", "must be in 16..1024");
  if (!(options.search_half_width_px >= 2 && options.search_half_width_px <= 200))
    throw InputError("search_half_width_px", "must be in [2, 200] px");
  if (!(options.fps > 0 && std::isfinite(options.fps))) throw InputError("fps", "must be > 0");
  if (options.exposure && !(*options.exposure > 0 && *options.exposure <= 1.0 / options.fps * 1.0001))
    throw InputError("--exposure", "must be > 0 and at most the frame time 1/fps");
  if (!(options.readout >= 0 && options.readout < 1.0 / options.fps))
    throw InputError("--readout", "must be >= 0 and below the frame time 1/fps");
  if (options.measure_readout && options.readout > 0)
    throw InputError("--readout", "give the readout or have it measured (auto), not both");
  if (!(options.point_spread_px >= 0.2 && options.point_spread_px <= 5))
    throw InputError("point_spread_px", "must be in [0.2, 5] px");
  Impl& m = *impl_;
  internal::OutlineGeometry& g = m.geometry;
  g.cal = calibration;
  g.a = body.across;
  g.s = body.across / body.along;
  g.eye = CameraCentre(calibration.pose);
  g.eye_s = Vector3d(g.eye.x(), g.s * g.eye.y(), g.eye.z());
  g.to_apparatus = calibration.pose.rotation.transpose();
  g.sigma_px = options.point_spread_px;
  m.row_delay = options.readout / calibration.camera.height;
  const double span = scene.x_max() - scene.x_low();
  m.x_lo = scene.x_low() + 1e-6 * span;
  m.x_hi = scene.x_max() - 1e-6 * span;

  // The near rail (on the camera's side) in front of the body: its band in the image, widened
  // by 2.5 px for the point spread and the sampling.
  const int width = calibration.camera.width, height = calibration.camera.height;
  m.occluder = cv::Mat::zeros(height, width, CV_8U);
  const double rod = scene.rod_radius() > 0 ? scene.rod_radius() : options.rail_radius;
  const double side = g.eye.y() < 0 ? -1.0 : 1.0;
  const Rails& rails = scene.rails();
  const Vector3d axis(1, side * rails.tan_half_alpha, rails.tan_theta);
  std::vector<cv::Point> polyline;
  double max_halfwidth = 0;
  const double x_end = 1.5 * scene.x_max() + 0.2;
  // Only where the lens model holds: beyond its reach a rail point far outside the picture would
  // be drawn inside it (a k3 < 0 lens folds back; a band across the picture hid most of the
  // body's outline on the ray-traced fast clips' true camera, and the ball was lost).
  m.lens_reach = LensModelReach(calibration.camera);
  for (int i = 0; i <= 400; ++i) {
    const Vector3d p = axis * (x_end * i / 400.0);
    const Vector3d pc = calibration.pose.rotation * p + calibration.pose.translation;
    if (pc.z() <= 0.05 || !m.WithinLens(pc)) continue;
    const Vector2d q = ProjectCameraPoint(calibration.camera, pc);
    if (std::abs(q.x()) > 1e5 || std::abs(q.y()) > 1e5) continue;
    polyline.emplace_back(static_cast<int>(std::lround(q.x() * 16)), static_cast<int>(std::lround(q.y() * 16)));
    max_halfwidth = std::max(max_halfwidth, rod * calibration.camera.fx / pc.z());
  }
  if (polyline.size() >= 2)
    cv::polylines(m.occluder, polyline, false, cv::Scalar(1),
                  std::max(1, static_cast<int>(std::ceil(2 * (max_halfwidth + 2.5)))), cv::LINE_8, 4);
  g.occluder = &m.occluder;
  m.shading = std::make_unique<internal::BodyShading>(g.s);
  g.shading = m.shading.get();
  m.edges = std::make_unique<internal::EdgeFit>(
      m.geometry, kEdgePoints, options.transfer == VideoTransfer::kLinear ? internal::Transfer::kLinear : internal::Transfer::kSrgb);

  // The band the body can sweep: discs along the centre path, a radius and a margin wider than
  // the body (the rays reach beyond the outline), for the background model.
  cv::Mat band = cv::Mat::zeros(height, width, CV_8U);
  const int steps = 2000;
  cv::Point last_at(-1 << 30, 0);
  int last_radius = -1;
  for (int i = 0; i <= steps; ++i) {
    const double x = m.x_lo + (m.x_hi - m.x_lo) * i / steps;
    const double z = scene.At(x).z;
    const Vector3d cam = calibration.pose.rotation * Vector3d(x, 0, z) + calibration.pose.translation;
    if (cam.z() <= 2 * g.a || !m.WithinLens(cam)) continue;
    const Vector2d q = g.Project(x, z);
    if (std::abs(q.x()) > 4 * width || std::abs(q.y()) > 4 * height) continue;
    const double r = m.RadiusPx(x, z) * std::max(1.0, 1.0 / g.s);
    const cv::Point at(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())));
    const int radius = static_cast<int>(std::ceil(1.6 * r + 16));
    if (at == last_at && radius == last_radius) continue;  // the same disc again
    cv::circle(band, at, radius, cv::Scalar(255), cv::FILLED);
    last_at = at, last_radius = radius;
  }
  m.background = std::make_unique<internal::BackgroundModel>(
      std::move(band), options.transfer == VideoTransfer::kLinear ? internal::Transfer::kLinear : internal::Transfer::kSrgb);
}

BallTracker::~BallTracker() = default;
BallTracker::BallTracker(BallTracker&&) noexcept = default;

std::vector<Vector2d> BallTracker::Outline(double x, double z, int n) const {
  return ProjectApparatusPoints(impl_->geometry.cal.camera, impl_->geometry.cal.pose, impl_->geometry.OutlinePoints(x, z, n));
}

std::optional<BallTracker::Exposure> BallTracker::ExposureEstimate() const {
  if (impl_->exposures.empty()) return std::nullopt;
  return Exposure{impl_->Exposure(), static_cast<int>(impl_->exposures.size())};
}

std::optional<BallTracker::Readout> BallTracker::ReadoutEstimate() const {
  if (impl_->row_delays.size() < kReadoutMinFrames) return std::nullopt;
  const double rows = impl_->geometry.cal.camera.height;
  Readout r;
  r.seconds = impl_->row_delay * rows;
  r.frames = static_cast<int>(impl_->row_delays.size());
  if (impl_->row_delay_u) {
    r.u = *impl_->row_delay_u * rows;
    r.frames = impl_->row_delay_frames;
  }
  return r;
}

std::optional<long> BallTracker::SceneChangedAt() const { return impl_->scene_changed_at; }

std::vector<std::pair<long, BallObservation>> BallTracker::TakeRevisions() {
  std::vector<std::pair<long, BallObservation>> out;
  out.swap(impl_->revisions);
  return out;
}

void BallTracker::Finish() {
  Impl& m = *impl_;
  m.SettleReadout();
  m.FitAgain(true);
  if (m.unconfirmed && m.frame_index > m.unconfirmed->frame) m.Withdraw();
}
const std::vector<long>& BallTracker::ExposureChanges() const { return impl_->exposure_changes; }

BallObservation BallTracker::Track(const cv::Mat& input) {
  Impl& m = *impl_;
  if (input.empty() || input.depth() != CV_8U || (input.channels() != 1 && input.channels() != 3))
    throw InputError("frame", "must be an 8-bit grey or BGR image");
  const CameraIntrinsics& camera = m.geometry.cal.camera;
  if (input.cols != camera.width || input.rows != camera.height)
    throw InputError("frame", "is " + std::to_string(input.cols) + "x" + std::to_string(input.rows) +
                                  " px but the camera calibration is for " + std::to_string(camera.width) + "x" +
                                  std::to_string(camera.height));
  cv::Mat converted;
  if (input.channels() == 1) cv::cvtColor(input, converted, cv::COLOR_GRAY2BGR);
  const cv::Mat& frame = input.channels() == 1 ? converted : input;
  const long f = ++m.frame_index;
  const double t = f / m.options.fps;

  // The reference time: the mid-exposure of the row where the centre lies at that time.
  std::optional<internal::MotionState> motion;
  if (const auto fit = m.Motion(f)) {
    motion = fit->AtOwnRow(t, m.row_delay, [&](const Vector2d& c) { return m.geometry.Project(c.x(), c.y()).y(); });
    if (!motion->centre.allFinite() || !motion->velocity.allFinite()) motion.reset();
  }
  const bool predicted = motion.has_value();
  if (m.unconfirmed && !predicted) m.Withdraw();  // not found again while it could be predicted
  Vector2d centre, velocity, acceleration;
  if (predicted) centre = motion->centre, velocity = motion->velocity, acceleration = motion->acceleration;
  cv::Rect region;
  if (predicted) region = m.BodyRegion(centre, velocity * m.Exposure());
  m.background->Measure(frame, region);
  m.WatchScene(f);
  const double gain = m.background->Gain();
  if (m.scene_changed_at) return {};

  // A frame the model measured. `acquired`: the body was found anew (not near the prediction).
  auto finish = [&](const FitOutcome& fit, const FitRequest& q, bool acquired) {
    const bool needs_model_before = m.needs_model;
    BallObservation o = m.Observe(fit, q);
    m.light_inverse_distance = fit.light_inverse_distance;
    if (fit.row_delay_sigma > 0 && m.MeasuredRowDelay(fit.row_delay)) m.KeepReadoutFrame(frame, gain, fit, q);
    m.noises.push_back(std::clamp(fit.noise, 1e-3, 0.2));
    if (m.noises.size() > 15) m.noises.pop_front();
    std::vector<double> sorted(m.noises.begin(), m.noises.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    m.noise = sorted[sorted.size() / 2];
    const bool confident = fit.misfit < 1.5 && fit.inliers >= kExposureMinAgreement * fit.rays_fitted;
    if (fit.rays_without_background == 0) m.confident_model_frame = f;
    const Vector2d fitted_velocity = q.velocity;
    const Vector2d smear(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]);
    // The exposure, from the smear against the track's speed (where the body moved > 3 px).
    const double step_px = fitted_velocity.norm() / m.options.fps / m.MetresPerPx(o.x, o.z);
    if (!m.options.exposure && confident && m.history.size() >= 3 && step_px > 3) {
      const double e = smear.dot(fitted_velocity) / fitted_velocity.squaredNorm();
      if (e > 0 && e < 1.5 / m.options.fps) m.exposures.push_back(e);
    }
    const bool motion_known = q.smear_sigma > 0.5 * m.MetresPerPx(o.x, o.z) * 1.01 || m.history.size() >= 2;
    // The edge fit at the model's centre: at acquisition it says whether this clip can take the
    // fast path (grey contrast, no pattern near the outline: it agrees with the model); where the
    // background under the body was never seen it stands in for the model until it is.
    bool edge_fallback = false;
    if (acquired || fit.rays_without_background > 0) {
      if (acquired) m.edges->Reset();
      const internal::EdgeFitOutcome e = m.edges->Measure(frame, o.x, o.z, kNarrowHalfWidthPx + 1);
      const double apart = e.ok ? (m.geometry.Project(e.x, e.z) - Vector2d(o.u, o.v)).norm() : 1e9;
      const bool agrees = m.Trusted(e) && apart < kFastMaxDisagreementPx + (fit.rays_without_background > 0 ? 0.5 : 0);
      if (acquired && !agrees) m.needs_model = true;
      if (fit.rays_without_background > 0 && agrees) {
        const double offset = o.time_offset;
        o = m.ObserveEdges(e);
        o.time_offset = offset;
        edge_fallback = true;
      }
    }
    m.LearnShading(frame, o, q.velocity);
    m.Remember(f, t, o);
    if (m.history.size() == 1 && fit.rays_without_background > 0) {
      if (m.unconfirmed) m.Withdraw();
      m.unconfirmed = Impl::Unconfirmed{f, needs_model_before};
    }
    m.KeepForRefit(f, t, frame, gain, fit, o, motion_known, edge_fallback);
    // Not while a scene change is being confirmed: the changed picture is not the background.
    // Near the body (what it uncovered since the last frame, and where the next frames' rays
    // read) where the model learnt the frame before; the whole band every kLearnEvery frames, as
    // on the fast path, and after any frame it did not learn (the body found anew, or measured
    // by the fast path): a still scene's background needs no more looks than that, normalised by
    // each frame's gain.
    if (m.scene_suspect == 0) {
      const cv::Rect body = m.BodyRegion(Vector2d(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]), smear);
      const int reach = static_cast<int>(std::ceil(2 * m.RadiusPx(o.x, o.z) + step_px)) + 2;
      const cv::Rect near(body.x - reach, body.y - reach, body.width + 2 * reach, body.height + 2 * reach);
      const bool whole = f % kLearnEvery == 0 || m.learnt_near_at != f - 1;
      m.background->Learn(frame, body, whole ? cv::Rect() : near);
      m.learnt_near_at = f;
    }
    m.FitAgain(false);
    return o;
  };

  // The fast path: the edge fit, where the scene does not need the model (see the header).
  if (predicted && !m.needs_model && m.row_delay == 0 && !m.MeasuresReadout(centre, velocity)) {
    const double px = 1 / m.MetresPerPx(centre.x(), centre.y());
    // With the exposure not yet known, and the body's shading known (so that the model measures
    // a long smear better than the edge fit), the blur is taken at its longest (a 360° shutter):
    // a longer blur than the fast path allows biases its edges (0.6 px on the first moving frames
    // of a shaded ball under a 360° shutter), and the model measures the exposure meanwhile.
    // Otherwise it is guessed (180°), and the edge fit's own checks decide up to a longer limit.
    const bool exposure_known = m.options.exposure || m.exposures.size() >= 3;
    const bool cautious = !exposure_known && m.shading->ready();
    const double exposure = cautious ? 1 / m.options.fps : m.Exposure();
    const double blur_px = velocity.norm() * exposure * px, step_px = velocity.norm() / m.options.fps * px;
    const double limit = exposure_known || cautious ? kFastMaxBlur : kFastMaxBlurGuessed;
    if (blur_px <= limit * m.RadiusPx(centre.x(), centre.y())) {
      const internal::EdgeFitOutcome e =
          m.edges->Measure(frame, centre.x(), centre.y(), m.options.search_half_width_px + 0.3 * step_px);
      const double off = e.ok ? (m.geometry.Project(e.x, e.z) - m.geometry.Project(centre.x(), centre.y())).norm() : 1e9;
      // Where the prediction missed by more than its usual error (the body just released, or
      // speeding up faster than the last frames said), the edge's ramp may be longer than the
      // blur predicted, run off the search window, and its truncated centroid lag toward the
      // prediction (0.7 px at 10 px per frame under a 360° shutter): the model measures the frame.
      const bool blur_holds = off < 1.0 + 0.1 * step_px;
      const bool trusted = m.Trusted(e) && off < std::max(4.0, 0.5 * m.RadiusPx(centre.x(), centre.y()) + step_px);
      if (trusted && blur_holds) {
        m.distrusted = 0;
        const BallObservation o = m.ObserveEdges(e);
        m.LearnShading(frame, o, velocity);
        m.Remember(f, t, o);
        if (f % kLearnEvery == 0 && m.scene_suspect == 0) m.background->Learn(frame, m.BodyRegion(Vector2d(e.x, e.z), velocity * m.Exposure()));
        m.FitAgain(false);
        return o;
      }
      if (!trusted && ++m.distrusted >= kFastDistrust) m.needs_model = true;
    }
  }
  if (predicted) {
    const double step_px = velocity.norm() / m.options.fps / m.MetresPerPx(centre.x(), centre.y());
    const FitRequest q = m.Request(centre, velocity, m.history.size() >= 2,
                                   m.options.search_half_width_px + 0.3 * step_px, acceleration);
    const FitOutcome fit = m.confident_model_frame == f - 1 && m.history.size() >= 3
                               ? m.MeasureNear({frame, {0, 0}, gain}, q)
                               : m.Measure({frame, {0, 0}, gain}, q);
    // Far from the prediction is a jump to something else unless the search confirms it.
    const double off = (m.geometry.Project(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]) -
                        m.geometry.Project(centre.x(), centre.y())).norm();
    if (m.Accept(fit, 0.45) && off < std::max(4.0, 0.5 * m.RadiusPx(centre.x(), centre.y()) + step_px)) return finish(fit, q, false);
  }
  // (Re)acquire: the initial guess in the first frame, else along the path near the prediction,
  // then along the whole path.
  std::vector<Vector2d> guesses;
  if (f == 0 && m.options.init_uv) {
    const Vector2d nrm = UndistortPixel(camera, *m.options.init_uv);
    const Vector3d ray = m.geometry.to_apparatus * Vector3d(nrm.x(), nrm.y(), 1.0);
    if (std::abs(ray.y()) > 1e-12) {
      const double s = -m.geometry.eye.y() / ray.y();
      if (s > 0) guesses.emplace_back(m.geometry.eye.x() + s * ray.x(), m.geometry.eye.z() + s * ray.z());
    }
  }
  if (predicted) {
    const double reach = 4 * m.geometry.a + 3 * velocity.norm() / m.options.fps;
    for (const Vector2d& c : m.Candidates(frame, gain, centre.x() - reach, centre.x() + reach)) guesses.push_back(c);
  }
  if (guesses.empty() || !predicted)
    for (const Vector2d& c : m.Candidates(frame, gain, m.x_lo, m.x_hi)) guesses.push_back(c);
  for (const Vector2d& guess : guesses) {
    // Without a prediction a candidate's fit depends on its window of the frame alone.
    const cv::Rect window = predicted ? cv::Rect() : m.BodyRegion(guess, Vector2d::Zero());
    if (!predicted && m.rejected.Unchanged(frame, window)) continue;
    const Vector2d v = predicted ? velocity : Vector2d::Zero();
    const FitRequest q = m.Request(guess, v, predicted && m.history.size() >= 2, 2 * m.options.search_half_width_px,
                                   predicted ? acceleration : Vector2d::Zero());
    const FitOutcome fit = m.Measure({frame, {0, 0}, gain}, q, Impl::Search::kAcquiring);
    if (!m.Accept(fit, 0.6)) {
      if (!predicted) m.rejected.Remember(frame, window);
    } else {
      m.rejected.Clear();
      const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
      if (!predicted || (m.geometry.Project(c.x(), c.y()) - m.geometry.Project(centre.x(), centre.y())).norm() >
                            2 * m.RadiusPx(c.x(), c.y()) + 3 * velocity.norm() / m.options.fps / m.MetresPerPx(c.x(), c.y()))
        m.history.clear();
      return finish(fit, q, !predicted);
    }
  }
  // Predicted past the path's ends (beyond the fall-off point the rails no longer carry it,
  // before x_low it has reached O) and not found: it fell or was taken off, and following its
  // prediction further costs full-model fits of an empty scene. The search along the path still
  // runs every frame.
  const bool off_the_path = predicted && (centre.x() > m.x_hi || centre.x() < m.x_lo);
  if (!predicted || off_the_path) m.history.clear();
  return {};
}

}  // namespace uphill
