// The tracker's acquire stage (tracker_state.hpp): the places along the path where the body is
// looked for anew, and the search that fits them.
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracker_state.hpp"

namespace uphill {

std::optional<BallTracker::Impl::Found> BallTracker::Impl::Acquire(const cv::Mat& frame, double gain, long f,
                                                                 const std::optional<Prediction>& near) {
  const bool predicted = near.has_value();
  std::vector<SearchStart> guesses;
  if (f == 0 && options.init_uv) {
    const Vector2d nrm = UndistortPixel(geometry.cal.camera, *options.init_uv);
    const Vector3d ray = geometry.to_apparatus * Vector3d(nrm.x(), nrm.y(), 1.0);
    if (std::abs(ray.y()) > 1e-12) {
      const double s = -geometry.eye.y() / ray.y();
      if (s > 0) guesses.push_back({Vector2d(geometry.eye.x() + s * ray.x(), geometry.eye.z() + s * ray.z()), std::nullopt});
    }
  }
  if (predicted) {
    const double reach = 4 * geometry.a + 3 * near->velocity.norm() / options.fps;
    for (const SearchStart& c : Candidates(frame, gain, near->centre.x() - reach, near->centre.x() + reach)) guesses.push_back(c);
  }
  if (guesses.empty() || !predicted)
    for (const SearchStart& c : Candidates(frame, gain, x_lo, x_hi)) guesses.push_back(c);
  // Near a prediction the first candidate accepted within a radius of it is the body. Found
  // anew, every candidate is fitted, and of the plausible fits (accepted, or accepted loosely
  // where the edge fit finds the body's outline; their ends standing out along the rods) the
  // best is taken if it stands out of its surroundings by
  // kAcquireMinStandOut noise levels at least (kAcquireMinStandOutSharp where its outline was
  // found sharp): a patch of the table's texture or a tape mark on a rod may fit an outline too,
  // but not by the contrast of a body.
  struct Plausible {
    FitOutcome fit;
    FitRequest request;
    size_t place;
    bool accepted;  // by Accept as a body near a prediction would be; else only its outline can make it one
  };
  std::vector<Plausible> plausible;
  std::vector<cv::Rect> windows;
  int fitted = 0;
  double lowest_residual = std::numeric_limits<double>::infinity();  // of any fit in this frame
  const int budget = f == 0 && !predicted ? kAcquireFitsFirstFrame : kAcquireFitsPerFrame;
  for (const SearchStart& place : guesses) {
    // Without a prediction a candidate's fit depends on its window of the frame alone.
    const cv::Rect window = predicted ? cv::Rect() : BodyRegion(place.at, Vector2d::Zero());
    if (!predicted && rejected.Unchanged(frame, window)) continue;
    bool body_here = false;
    for (const std::optional<Vector2d>& guess : {std::optional<Vector2d>(place.at), place.again}) {
      if (!guess || body_here || fitted >= budget) continue;
      ++fitted;
      const Vector2d v = predicted ? near->velocity : Vector2d::Zero();
      const FitRequest q = Request(*guess, v, predicted && history.size() >= 2, 2 * options.search_half_width_px,
                                   predicted ? near->acceleration : Vector2d::Zero());
      const FitOutcome fit = Measure({frame, {0, 0}, gain}, q, Search::kAcquiring);
      if (fit.ok && fit.inliers > 0) lowest_residual = std::min(lowest_residual, fit.noise);
      // Found anew, a fit is plausible at the clip's noise level too, and with fewer rays agreeing:
      // a print's stripes raise a body's own residuals to several times the pixel noise, its dots
      // near the limb cost rays. Such a fit is the body only where its outline is found (below).
      const bool accepted = Accept(fit, kAcquireAgreement);
      if (!accepted && (predicted || !Accept(fit, kAcquireLooseAgreement, noise, kAcquireLooseMinLevels))) continue;
      if (!EndsStandOut({frame, {0, 0}, gain}, fit, q)) continue;
      const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
      if (predicted) {
        // A body rolling on the rails does not leave its predicted path by more than a radius
        // (and three frames' travel): a place farther off is something else (a reflection, the
        // rails' crossing).
        if ((geometry.Project(c.x(), c.y()) - geometry.Project(near->centre.x(), near->centre.y())).norm() >
            RadiusPx(c.x(), c.y()) + 3 * near->velocity.norm() / options.fps / MetresPerPx(c.x(), c.y()))
          continue;
        rejected.Clear();
        return Found{fit, q, std::nullopt, false};
      }
      body_here = accepted;
      plausible.push_back({fit, q, windows.size(), accepted});
    }
    if (!predicted) windows.push_back(window);
    if (fitted >= budget) break;
  }
  // The frame's noise level: the lowest residual any fit of this frame reached, plausible or not
  // (and at least the clip's). Every place of one frame has the same pixel noise; a body's print,
  // reflections or shading only add to its own fit's residuals. Where the body is the only
  // plausible place, its own residuals would otherwise be the frame's noise: a dark ball at rest
  // between thick dark rods, its outline found all round at 161 grey levels, stood out by 9.1 of
  // its own fit's residuals and was found in none of its frames.
  const double frame_noise = noises.empty() && std::isfinite(lowest_residual) ? std::max(noise, lowest_residual) : noise;
  std::optional<Found> best;
  double best_score = 0;
  std::vector<bool> body_at(windows.size(), false);
  // Where no place is a body, the outlines are looked for again with edges of either sign on
  // every ray: a two-tone spheroid against a wall between its two greys (purple and yellow-green
  // on grey) steps up on one half and down on the other, so that edges of one sign found half its
  // outline, and it was found in none of its 30 frames. Only then: with either sign a place of a
  // two-tone ball's surroundings 60 px off it had its outline found, where one sign found it in
  // part only and the ball itself stood out more.
  for (const bool either_sign : {false, true}) {
    if (either_sign && best) break;
    for (const Plausible& p : plausible) {
      if (either_sign && p.fit.rays_without_background == 0) continue;  // the same as the first time
      // Where the background is unknown, the edge fit looks for the body's outline: a print or a
      // reflection can hold the model's outline off a body, a patch of the table has no such
      // outline.
      std::optional<internal::EdgeFitOutcome> outline;
      if (p.fit.rays_without_background > 0) {
        edges->Reset();
        edges->EitherPolarity(either_sign);
        outline = edges->Measure(frame, p.fit.p[internal::kCentreX], p.fit.p[internal::kCentreZ], 2 * options.search_half_width_px);
        edges->EitherPolarity(false);
      }
      // A faint outline counts where its edges lie on it sharply (FaintOutlineFound): a dark body in
      // dim light steps by fewer grey levels than the fast path asks for, and stands out of the
      // noise less than a body in good light, but no patch of the table has its edges that sharply
      // on one outline.
      const bool faint = outline && !OutlineFound(*outline) && FaintOutlineFound(*outline);
      // A place whose outline the picture shows nowhere but through the near rail's band (fewer
      // rays in view than an edge fit needs, searched as wide as here) is not a body: the rods'
      // edges run along the path and meet an outline anywhere between them, and a model fit there
      // can stand out more than the body beside it (a banded ball behind a 5.3 mm rod: a place over
      // the rods 19 mm down the path stood out by 32 noise levels, the ball by 13).
      if (outline && outline->attempted < internal::kEdgeFitMinPoints) continue;
      const bool found_outline = outline && (OutlineFound(*outline) || faint), clean = outline && CleanOutline(*outline);
      // Its stand-out in its own fit's noise levels, or, where its outline was found (a printed
      // body's own residuals hold its print), in the frame's. Where the edge fit found the outline
      // elsewhere (a dotted body's print pulled the model 10 px along the path), the contrast is
      // also read from the model fitted again there, and the better of the two fits counts: the
      // contrast belongs to the body's outline, wherever the print pulled the first fit. Which of
      // the two positions measures the frame is decided below, as for any found outline.
      if (!p.accepted && !found_outline) continue;
      const FitOutcome at_outline = found_outline ? ContrastAtOutline(frame, gain, *outline, p.fit) : p.fit;
      const double stand_out = at_outline.contrast / std::max(noise, at_outline.noise);
      const double least = faint || (found_outline && SharpOutline(*outline)) ? kAcquireMinStandOutSharp : kAcquireMinStandOut;
      if (stand_out < least && !(found_outline && at_outline.contrast / frame_noise >= least)) continue;
      body_at[p.place] = true;
      // A clean outline all round comes before any other, then an outline found where it was
      // looked for, then one found in part, then the stand-out. Where the outline was found it
      // measures the frame if the model put the body elsewhere (below).
      const bool partly_found = outline && OutlinePartlyFound(*outline);
      const double score = stand_out + (clean ? 1e6 : 0) + (found_outline ? 1e3 : 0) + (partly_found ? 1e2 : 0);
      if (!best || score > best_score) best = Found{p.fit, p.request, found_outline ? outline : std::nullopt}, best_score = score;
    }
  }
  for (size_t k = 0; k < windows.size(); ++k)
    if (!body_at[k]) rejected.Remember(frame, windows[k]);
  if (!best) return std::nullopt;
  best->anew = true;
  rejected.Clear();
  history.clear();
  // The edge fit measures the frame only where it disagrees with the model: where they agree
  // the model's fit stands, as everywhere else.
  const bool disagree = best->outline && (geometry.Project(best->outline->x, best->outline->z) -
                                          geometry.Project(best->fit.p[internal::kCentreX], best->fit.p[internal::kCentreZ]))
                                             .norm() > kFastMaxDisagreementPx;
  if (!disagree) best->outline.reset();
  return best;
}

std::optional<BallTracker::Impl::Found> BallTracker::Impl::ConfirmedElsewhere(const cv::Mat& frame, double gain,
                                                                              const Vector2d& tracked) {
  const internal::FrameView view{frame, {0, 0}, gain};
  if (SilhouetteOf(view, tracked, 0) == Silhouette::kConfirms) return std::nullopt;
  const Vector2d here = geometry.Project(tracked.x(), tracked.y());
  const double apart = 2 * RadiusPx(tracked.x(), tracked.y());
  auto away = [&](const Vector2d& c) { return (geometry.Project(c.x(), c.y()) - here).norm() >= apart; };
  int fitted = 0;
  for (const SearchStart& place : Candidates(frame, gain, x_lo, x_hi)) {
    if (!away(place.at)) continue;
    if (++fitted > kAcquireFitsPerFrame) break;
    const FitRequest q = Request(place.at, Vector2d::Zero(), false, 2 * options.search_half_width_px);
    const FitOutcome fit = Measure(view, q, Search::kAcquiring);
    const Vector2d c(fit.p[internal::kCentreX], fit.p[internal::kCentreZ]);
    if (!away(c) || !Accept(fit, kAcquireAgreement) || !EndsStandOut(view, fit, q)) continue;
    const double smear_px = SmearPx(c, Vector2d(fit.p[internal::kSmearX], fit.p[internal::kSmearZ]));
    if (SilhouetteOf(view, c, smear_px) == Silhouette::kConfirms) return Found{fit, q, std::nullopt, true};
  }
  return std::nullopt;
}

FitOutcome BallTracker::Impl::ContrastAtOutline(const cv::Mat& frame, double gain, const internal::EdgeFitOutcome& outline,
                                                const FitOutcome& fit) {
  const Vector2d at(outline.x, outline.z);
  if ((geometry.Project(at.x(), at.y()) - geometry.Project(fit.p[internal::kCentreX], fit.p[internal::kCentreZ])).norm() <=
      kFastMaxDisagreementPx)
    return fit;
  FitOutcome refit = Measure({frame, {0, 0}, gain}, Request(at, Vector2d::Zero(), false, 2 * options.search_half_width_px),
                             Search::kAcquiring);
  const bool better = refit.ok && refit.contrast / std::max(noise, refit.noise) > fit.contrast / std::max(noise, fit.noise);
  return better ? refit : fit;
}

std::vector<BallTracker::Impl::SearchStart> BallTracker::Impl::Candidates(const cv::Mat& frame, double gain, double x0, double x1) const {
  x0 = std::max(x0, x_lo);
  x1 = std::min(x1, x_hi);
  if (!(x1 > x0)) return {};
  const int n = 32;
  // Candidates a quarter radius apart in the image.
  const Vector2d p0 = geometry.Project(x0, scene.At(x0).z), p1 = geometry.Project(x1, scene.At(x1).z);
  const double r_mid = RadiusPx(0.5 * (x0 + x1), scene.At(0.5 * (x0 + x1)).z);
  const int count = std::clamp(static_cast<int>((p1 - p0).norm() / std::max(1.0, 0.25 * r_mid)) + 1, 8, 2000);
  std::vector<std::pair<double, double>> scored, stepped;  // (score, x)
  std::vector<cv::Vec3f> inside(n), outside(n);
  std::vector<double> edge_steps(n);
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
      const Vector2d just_in = image[k] - 2.0 * dir;
      const cv::Vec3f across = outside[used] - internal::SampleLinear(frame, background->table(), just_in.x(), just_in.y());
      edge_steps[used] = (across[0] + across[1] + across[2]) / 3;
      if (background->Known(pin.x(), pin.y()) && background->Known(pout.x(), pout.y())) {
        bg_in.push_back(cv::norm(inside[used] - background->At(pin.x(), pin.y()) * gain));
        bg_out.push_back(cv::norm(outside[used] - background->At(pout.x(), pout.y()) * gain));
      }
      ++used;
    }
    // A third of the outline at least: the near rail's band is drawn at the rod's widest
    // (near_rail_band.hpp), and from a low camera it hides up to half of a body's outline that
    // the rod itself barely covers.
    if (used < n / 3) continue;
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
    // Appearance-free: the grey step across the outline, its median over the rays (a body
    // lighter or darker than its surroundings as a whole, whatever its print or its colours:
    // a two-tone ball on paper matches the paper with one half).
    std::nth_element(edge_steps.begin(), edge_steps.begin() + used / 2, edge_steps.begin() + used);
    stepped.emplace_back(std::abs(edge_steps[used / 2]), xc);
  }
  // The best by colour and the best by the outline's step, each a radius from the others of its
  // kind (a fit started there reaches the body within a radius) and the search's half-width from
  // the other kind's (a fit started there sees the same outline; one started a quarter radius
  // off a printed body's centre may not reach it). Not quite for a body more than 12 px in
  // radius (the acquiring fit looks 2 search half-widths either side of its outline): it can lie
  // between two places, each too far off. Places that close cost the first frame's search more
  // fits than the speed goal leaves (docs/track.md, "Accuracy"), so a second start is tried only
  // where the first found no body: a body's colour score is a plateau, about as high wherever
  // the outline stays on the body's colour with its outside off it, and a print's dot or a
  // highlight can lift any place of it. Where the plateau's centre lies a quarter radius or more
  // from its highest place, it is the second start; else the higher of its two neighbours on the
  // plateau (a dotted spheroid at rest, 35 px in radius, whose highest place lay a third of a
  // radius off its centre, was found in none of its frames without it).
  const std::vector<std::pair<double, double>> colour_along = scored;  // in x order
  std::vector<SearchStart> out;
  auto take = [&](std::vector<std::pair<double, double>>& by, size_t most, bool plateau) {
    std::sort(by.begin(), by.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    const size_t before = out.size();
    for (const auto& [score, xc] : by) {
      if (score < options.min_contrast || out.size() - before >= most) break;
      const Vector2d p = geometry.Project(xc, scene.At(xc).z);
      const double r = RadiusPx(xc, scene.At(xc).z);
      bool near = false;
      for (size_t i = 0; i < out.size(); ++i)
        near = near || (geometry.Project(out[i].at.x(), out[i].at.y()) - p).norm() < (i >= before ? r : options.search_half_width_px);
      if (near) continue;
      SearchStart place{Vector2d(xc, scene.At(xc).z), std::nullopt};
      const double centre = plateau ? PlateauCentre(colour_along, xc) : xc;
      if ((geometry.Project(centre, scene.At(centre).z) - p).norm() >= 0.25 * r)
        place.again = Vector2d(centre, scene.At(centre).z);
      else if (const std::optional<double> side = plateau ? PlateauNeighbour(colour_along, xc) : std::nullopt)
        place.again = Vector2d(*side, scene.At(*side).z);
      out.push_back(place);
    }
  };
  take(scored, kCandidatesByColour, true);
  take(stepped, kCandidatesByStep, false);
  return out;
}

// The score-weighted mean x of the run of places, along the path, around the one at `peak` whose
// scores stay within kPlateauShare of its score.
double BallTracker::Impl::PlateauCentre(const std::vector<std::pair<double, double>>& along, double peak) {
  const auto at = std::find_if(along.begin(), along.end(), [&](const auto& s) { return s.second == peak; });
  const double floor = kPlateauShare * at->first;
  auto first = at, last = at;
  while (first != along.begin() && std::prev(first)->first >= floor) --first;
  while (std::next(last) != along.end() && std::next(last)->first >= floor) ++last;
  double weight = 0, sum = 0;
  for (auto s = first; s != std::next(last); ++s) weight += s->first, sum += s->first * s->second;
  return sum / weight;
}

// Of the two places next to the one at `peak` along the path, the one that scores higher, if it
// belongs to the peak's plateau (kPlateauShare of its score).
std::optional<double> BallTracker::Impl::PlateauNeighbour(const std::vector<std::pair<double, double>>& along, double peak) {
  const auto at = std::find_if(along.begin(), along.end(), [&](const auto& s) { return s.second == peak; });
  std::optional<std::pair<double, double>> best;
  if (at != along.begin()) best = *std::prev(at);
  if (std::next(at) != along.end() && (!best || std::next(at)->first > best->first)) best = *std::next(at);
  if (!best || best->first < kPlateauShare * at->first) return std::nullopt;
  return best->second;
}

}  // namespace uphill
