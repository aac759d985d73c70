// The tracker's opening stage (tracker_state.hpp): the first frames of a clip, kept until the
// body is found where the background confirms it, and measured again at the end of the clip,
// backwards from there, with the background the rest of the clip has shown.
//
// Why backwards: a body at rest from the first frame hides the background under it, and the
// first frames are measured without it (per-ray backgrounds, the edge fit), which a mirror ball,
// a print or a textured table can mislead. Once the body has rolled away, the background under
// its resting place is known, and the first frame the background confirms is a prediction for
// the one before it: the same search the tracker runs forwards, run in reverse.
#include <algorithm>
#include <cmath>
#include <span>

#include "tracker_state.hpp"

namespace uphill {

BallTracker::Impl::Silhouette BallTracker::Impl::SilhouetteOf(const internal::FrameView& view, const Vector2d& centre,
                                                              double smear_px) const {
  // Samples on rings inside the outline (its projected points drawn towards the centre's pixel)
  // and just outside it, clear of the limb, where the smear and the point spread blend body and
  // background. Inside, most samples must differ from the background; outside, most must match
  // it (the shadow and a print that matches the table cost a few): a fit half a radius off
  // has a third of its outer ring on the body. A smeared body covers the outer ring where it
  // passed during the exposure: those samples (within a radius of the smear's segment, which
  // lies along the path) are not the background's.
  constexpr int kPoints = 24;
  constexpr double kInside[] = {0.3, 0.55, 0.75}, kOutside[] = {1.15, 1.3};
  const Vector2d c = geometry.Project(centre.x(), centre.y());
  const Vector2d along = (geometry.Project(centre.x() + 1e-3 * PathTangent(centre.x()).x(),
                                           centre.y() + 1e-3 * PathTangent(centre.x()).y()) - c).normalized();
  const Vector2d half_smear = 0.5 * smear_px * along;
  const std::vector<Vector2d> outline =
      ProjectApparatusPoints(geometry.cal.camera, geometry.cal.pose, geometry.OutlinePoints(centre.x(), centre.y(), kPoints));
  const std::array<float, 256>& linear = background->table();
  const double threshold = std::max(kSilhouetteMinContrast, kSilhouetteNoiseLevels * noise);
  struct Count {
    int samples = 0, known = 0, differ = 0;
  };
  auto count = [&](std::span<const double> rings) {
    Count n;
    for (const Vector2d& edge : outline) {
      for (const double s : rings) {
        const Vector2d p = c + s * (edge - c);
        if (s > 1 && smear_px > 0) {
          const double t = std::clamp((p - c).dot(half_smear) / half_smear.squaredNorm(), -1.0, 1.0);
          if ((p - c - t * half_smear).norm() < 1.1 * (edge - c).norm()) continue;
        }
        const int fx = static_cast<int>(std::lround(p.x())), fy = static_cast<int>(std::lround(p.y()));
        const int wx = fx - view.origin.x, wy = fy - view.origin.y;
        if (wx < 0 || wy < 0 || wx >= view.bgr.cols || wy >= view.bgr.rows) continue;
        if (occluder.at<std::uint8_t>(fy, fx)) continue;  // the near rail: neither body nor background
        ++n.samples;
        if (!background->Known(p.x(), p.y())) continue;
        ++n.known;
        const cv::Vec3b pixel = view.bgr.at<cv::Vec3b>(wy, wx);
        const cv::Vec3f behind = background->At(p.x(), p.y());
        double differs = 0;
        for (int ch = 0; ch < 3; ++ch) differs = std::max(differs, std::abs(linear[pixel[ch]] / view.gain - behind[ch]));
        if (differs > threshold) ++n.differ;
      }
    }
    return n;
  };
  const Count inside = count(kInside), outside = count(kOutside);
  auto decided = [](const Count& n) { return n.samples > 0 && n.known >= kSilhouetteMinKnownShare * n.samples; };
  if (!decided(inside) || !decided(outside)) return Silhouette::kUndecided;
  return inside.differ >= kSilhouetteMinBodyShare * inside.known &&
                 outside.known - outside.differ >= kSilhouetteMinBackgroundShare * outside.known
             ? Silhouette::kConfirms
             : Silhouette::kContradicts;
}

double BallTracker::Impl::SmearOf(long f, const BallObservation& o) const {
  // The fast path fits no smear: the step to a neighbouring frame's centre over the exposure.
  double step_px = 0;
  for (const long g : {f - 1, f + 1}) {
    const auto it = samples.find(g);
    if (it == samples.end()) continue;
    step_px = std::max(step_px, (geometry.Project(it->second.x, it->second.z) - Vector2d(o.u, o.v)).norm());
  }
  return std::max(o.smear_px, step_px * Exposure() * options.fps);
}

void BallTracker::Impl::KeepOpening(long f, double t, const cv::Mat& frame, const BallObservation& o) {
  if (opening_closed) return;
  const cv::Rect box = background->box() & cv::Rect(0, 0, frame.cols, frame.rows);
  const size_t bytes = box.area() * 3u;
  if (box.empty() || opening_bytes + bytes > kOpeningBytes) {
    opening_closed = true;
    return;
  }
  opening.push_back({f, t, background->Gain(), frame(box).clone(), box.tl(), o});
  opening_bytes += bytes;
  const OpeningFrame& kept = opening.back();
  const bool confirmed =
      o.found && SilhouetteOf({kept.window, kept.origin, kept.gain}, Vector2d(o.x, o.z), SmearOf(f, o)) == Silhouette::kConfirms;
  opening_confirmed_run = confirmed ? opening_confirmed_run + 1 : 0;
  if (opening_confirmed_run < kOpeningAnchorFrames) return;
  opening_closed = true;
  // Found and confirmed from the first frame on: nothing to measure again.
  if (opening.size() == static_cast<size_t>(kOpeningAnchorFrames)) {
    opening.clear();
    opening.shrink_to_fit();
    opening_bytes = 0;
  }
}

void BallTracker::Impl::RecoverOpening() {
  if (opening.empty()) return;
  // The observations as reported so far: the revisions not yet handed out apply on top.
  for (const auto& [k, revised] : revisions)
    for (OpeningFrame& kept : opening)
      if (kept.frame == k) kept.observed = revised;
  auto view = [](const OpeningFrame& k) { return internal::FrameView{k.window, k.origin, k.gain}; };
  auto silhouette = [&](const OpeningFrame& k) {
    return SilhouetteOf(view(k), Vector2d(k.observed.x, k.observed.z), SmearOf(k.frame, k.observed));
  };
  auto confirmed = [&](const OpeningFrame& k) { return k.observed.found && silhouette(k) == Silhouette::kConfirms; };
  // A position the background contradicts (the inside looks like the table, or the outside like
  // a body): one the background does not show is kept as the tracker found it, for want of a
  // better look (the body never left the place for long enough).
  auto contradicted = [&](const OpeningFrame& k) { return k.observed.found && silhouette(k) == Silhouette::kContradicts; };
  // The anchor: the first run of confirmed frames, judged with the background as learnt by now.
  // Where there is none (a body that moved less than its diameter leaves the background under
  // every place it took unseen: a banded ball pushed from rest, coming to rest 25 mm on, 55 mm
  // across, lost its 3 frames before the push), the first run of found frames the background
  // does not contradict.
  const int n = static_cast<int>(opening.size());
  auto first_run = [&](auto&& counts) {
    for (int i = 0, run = 0; i < n; ++i) {
      run = counts(opening[i]) ? run + 1 : 0;
      if (run == kOpeningAnchorFrames) return i - run + 1;
    }
    return -1;
  };
  int anchor = first_run(confirmed);
  // From such a run the background cannot judge better than it did when the frames were tracked:
  // only the frames before it that were not found are measured again.
  const bool unconfirmed_anchor = anchor < 0;
  if (unconfirmed_anchor) anchor = first_run([&](const OpeningFrame& k) { return k.observed.found && !contradicted(k); });
  if (anchor < 0) {
    // No run found in the opening (or the memory ran out first): nothing to start from.
    opening.clear();
    return;
  }
  auto report = [&](OpeningFrame& k, const BallObservation& o) {
    const bool changed = o.found != k.observed.found ||
                         (o.found && std::hypot(o.u - k.observed.u, o.v - k.observed.v) > 1e-9);
    if (!changed) return;
    k.observed = o;
    revisions.emplace_back(k.frame, o);
    if (o.found) samples[k.frame] = SampleOf(k.t, o);
    else samples.erase(k.frame);
  };
  // From the anchor's run outwards: backwards to the first frame, and forwards over the frames
  // kept after it that the background does not confirm. Each frame is predicted from the two
  // next to it on the anchor's side (constant velocity; a body at rest stays), searched as a
  // tracked frame is, and accepted unless the background contradicts it.
  auto sweep = [&](int from, int to, int step) {
    const int last = from - step;  // the run's frame next to `from`
    Vector2d next(opening[last].observed.x, opening[last].observed.z);
    Vector2d after(opening[last - step].observed.x, opening[last - step].observed.z);
    int misses = 0;
    for (int i = from; i != to; i += step) {
      OpeningFrame& k = opening[i];
      if ((step > 0 && confirmed(k)) || (unconfirmed_anchor && k.observed.found)) {
        after = next;
        next = Vector2d(k.observed.x, k.observed.z);
        misses = 0;
        continue;
      }
      if (misses > kOpeningMaxMisses) {
        // Beyond the search's reach: a frame the background contradicts is not reported.
        if (contradicted(k)) report(k, BallObservation{});
        continue;
      }
      const Vector2d predicted = 2 * next - after;
      const Vector2d velocity = (next - after) * options.fps * step;  // forwards in time
      const double step_px = velocity.norm() / options.fps / MetresPerPx(next.x(), next.y());
      const FitRequest q = Request(predicted, velocity, true, options.search_half_width_px + 0.3 * step_px);
      const FitOutcome fit = Measure(view(k), q);
      const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
      const double off = (geometry.Project(c.x(), c.y()) - geometry.Project(predicted.x(), predicted.y())).norm();
      after = next;
      bool accepted = Accept(fit, 0.45) && off < std::max(4.0, 0.5 * RadiusPx(c.x(), c.y()) + step_px) &&
                      EndsStandOut(view(k), fit, q);
      BallObservation o;
      if (accepted) {
        o = Observe(fit, q);
        accepted = SilhouetteOf(view(k), c, std::max(o.smear_px, step_px * Exposure() * options.fps)) !=
                   Silhouette::kContradicts;
      }
      if (accepted) {
        report(k, o);
        next = c;
        misses = 0;
      } else {
        if (contradicted(k)) report(k, BallObservation{});
        next = predicted;
        ++misses;
      }
    }
  };
  if (anchor > 0) sweep(anchor - 1, -1, -1);
  if (!unconfirmed_anchor && anchor + kOpeningAnchorFrames < n) sweep(anchor + kOpeningAnchorFrames, n, 1);
  opening.clear();
  opening_bytes = 0;
}

}  // namespace uphill
