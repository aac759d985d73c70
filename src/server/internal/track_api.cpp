#include "track_api.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "app/video_frames.hpp"
#include "app/video_trials.hpp"
#include "io/experiment.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "report/video_trials.hpp"
#include "server/row_check.hpp"
#include "video_upload.hpp"

namespace uphill::internal {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

int RowIndex(const StoreSnapshot& snapshot, std::int64_t id) {
  const int index = snapshot.state.IndexOf(id);
  if (index < 0) throw InputError("row", "row " + std::to_string(id) + " does not exist");
  if (snapshot.state.rows[index].video.empty())
    throw InputError("video", "trial " + snapshot.state.rows[index].trial + " has no video: attach one first");
  return index;
}

VideoTrialResult Track(const ExperimentStore& store, const StoreSnapshot& snapshot, std::int64_t id) {
  const int index = RowIndex(snapshot, id);
  VideoTrialResult r = TrackTrialVideo(store.directory(), static_cast<std::size_t>(index));
  if (!r.trial.error.empty()) throw InputError("video", r.trial.error);
  return r;
}

std::string Number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

ordered_json TrackRowVideo(const ExperimentStore& store, const StoreSnapshot& snapshot, std::int64_t id) {
  const std::string& unit = snapshot.state.unit;
  const auto L = [&](double si) { return ToUnit(si, Dimension::kLength, unit); };
  const auto measured = [&](const std::optional<Estimate>& m, bool length) -> ordered_json {
    if (!m) return nullptr;
    return {{"value", length ? L(m->value) : m->value},
            {"u", m->u ? ordered_json(length ? L(*m->u) : *m->u) : ordered_json(nullptr)}};
  };
  const VideoTrialResult r = Track(store, snapshot, id);
  const VideoTrial& t = r.trial;
  const VideoProbe probe = ProbeVideo(store.directory() + "/" + t.video, t.video);
  ordered_json out;
  out["row"] = id;
  out["video"] = t.video;
  out["frames"] = t.frames;
  out["frames_tracked"] = t.found;
  out["partial"] = t.partial;
  out["partial_reason"] = t.partial_reason;
  out["release"] = t.release_x ? ordered_json{{"x0", measured(t.release_x, true)}, {"t0", measured(t.release_t, false)}}
                               : ordered_json(nullptr);
  // The direction of the first motion: from the release toward O (down the rails) or away.
  std::string direction;
  for (const TrackFrame& f : r.track.frames)
    if (f.found && t.release_t && f.t > t.release_t->value + 0.1 && t.release_x) {
      direction = f.x < t.release_x->value ? "toward O (down the rails)" : "away from O (up the rails)";
      break;
    }
  out["direction"] = direction;
  ordered_json turns = ordered_json::array();
  for (const TrackEvent& e : t.events)
    if (e.kind == "turning point") turns.push_back({{"x", L(e.x.value)}, {"t", e.t.value}});
  out["turns"] = turns;
  if (t.rest) {
    double rest_t = 0;
    for (const TrackEvent& e : t.events)
      if (e.kind == "comes to rest") rest_t = e.t.value;
    out["rest"] = {{"y", measured(t.rest, true)}, {"t", rest_t}};
  } else {
    out["rest"] = nullptr;
  }
  out["never_at_rest"] = t.no_rest;
  if (t.fit_available && t.fit_value) {
    const bool mu = t.fitted == "mu";
    char text[200];
    std::snprintf(text, sizeof text, "%s = %.4g ± %.2g%s, χ²/ν = %.2f (ν = %d)", mu ? "μ" : "g_eff",
                  t.fit_value->value, t.fit_value->u.value_or(0), mu ? "" : " m/s²", t.reduced_chi2, t.dof);
    out["fit"] = {{"text", text}};
  } else {
    out["fit"] = {{"text", "not available: " + t.fit_unavailable}};
  }
  out["warnings"] = t.notes;
  // A Y typed in the row is compared with the video's, by the report's rule (CompareY): a video
  // of another setting attached to the trial shows here, before its Y is accepted.
  const Row& row = snapshot.state.rows[static_cast<std::size_t>(RowIndex(snapshot, id))];
  const RowCheck check = CheckRow(snapshot.state, row);
  out["typed_y"] = nullptr;
  if (t.rest && t.rest->u && check.y) {
    const YComparison c = CompareY(*check.y, check.u_y.value_or(0), t.rest->value, *t.rest->u);
    out["typed_y"] = {{"typed", L(c.typed)}, {"video", L(c.video)}, {"difference", L(c.difference)},
                      {"sigma", L(c.sigma)}, {"flagged", c.flagged}};
    if (c.flagged) {
      char text[300];
      std::snprintf(text, sizeof text,
                    "the typed Y = %.6g %s and the video's rest position %.6g %s differ by %.3g %s, more than 3 "
                    "combined standard uncertainties (%.2g %s): is this the trial's recording, and its scene?",
                    L(c.typed), unit.c_str(), L(c.video), unit.c_str(), L(c.difference), unit.c_str(), L(c.sigma),
                    unit.c_str());
      out["warnings"].push_back(text);
    }
  }
  out["width"] = probe.width;
  out["height"] = probe.height;
  ordered_json strip = ordered_json::array();
  const std::size_t n = r.track.frames.size();
  for (std::size_t k = 0; k < 8 && n > 0; ++k) {
    const TrackFrame& f = r.track.frames[std::min(n - 1, k * (n - 1) / 7)];
    if (!strip.empty() && strip.back()["frame"] == f.frame) continue;
    strip.push_back({{"frame", f.frame},
                     {"t", f.t},
                     {"u", f.found ? ordered_json(f.u) : ordered_json(nullptr)},
                     {"v", f.found ? ordered_json(f.v) : ordered_json(nullptr)},
                     {"radius_px", f.found ? ordered_json(f.radius_px) : ordered_json(nullptr)},
                     {"x", f.found ? ordered_json(L(f.x)) : ordered_json(nullptr)},
                     {"u_x", f.found && f.u_x > 0 ? ordered_json(L(f.u_x)) : ordered_json(nullptr)}});
  }
  out["strip"] = strip;
  return out;
}

RestAsY RowRestAsY(const ExperimentStore& store, const StoreSnapshot& snapshot, std::int64_t id) {
  const VideoTrialResult r = Track(store, snapshot, id);
  if (!r.trial.rest)
    throw InputError("video", "the body never comes to rest in " + r.trial.video +
                                  (r.trial.no_rest.empty() ? "" : " (" + r.trial.no_rest + ")") + ": no Y to accept");
  const std::string& unit = snapshot.state.unit;
  return {Number(ToUnit(r.trial.rest->value, Dimension::kLength, unit)),
          r.trial.rest->u ? Number(ToUnit(*r.trial.rest->u, Dimension::kLength, unit)) : ""};
}

namespace {

// The file `video` moved into kDetachedVideoFolder unless a row of `after` names it; its new path,
// or "" when left in place (still used, or already gone).
std::string SetDetachedVideoAside(const ExperimentStore& store, const StoreSnapshot& after, const std::string& video) {
  for (const Row& row : after.state.rows)
    if (row.video == video) return "";  // another trial films the same recording
  const ContainedDirectory* folder = store.folder();
  if (!folder || KindInFolder(*folder, video, "video") != ContainedDirectory::Kind::kFile) return "";
  const std::filesystem::path path(video);
  std::optional<ContainedDirectory> subfolder;
  if (path.has_parent_path()) subfolder.emplace(folder->Subdirectory(path.parent_path().generic_string(), false));
  const ContainedDirectory& from = subfolder ? *subfolder : *folder;
  const ContainedDirectory aside = folder->Subdirectory(kDetachedVideoFolder, true);
  std::string target = path.filename().string();
  for (int n = 2; aside.KindOf(target) != ContainedDirectory::Kind::kAbsent; ++n)
    target = path.stem().string() + "-" + std::to_string(n) + path.extension().string();
  from.MoveFile(path.filename().string(), aside, target);
  return std::string(kDetachedVideoFolder) + "/" + target;
}

}  // namespace

DetachedVideo DetachRowVideo(ExperimentStore& store, std::int64_t version, std::int64_t id, std::mutex& track_mutex) {
  const StoreSnapshot s = store.Get();
  const int index = s.state.IndexOf(id);
  if (index < 0) throw InputError("row", "row " + std::to_string(id) + " does not exist");
  const Row& old = s.state.rows[index];
  if (old.video.empty()) throw InputError("video", "trial " + old.trial + " has no video to detach");
  ordered_json row = ToJson(old);
  row.erase("video");
  if (!row.contains("Y"))
    throw InputError("video", "trial " + old.trial +
                                  " has no Y: without its video it would measure nothing (type its Y first, or delete "
                                  "the trial)");
  DetachedVideo out;
  out.video = old.video;
  out.after = store.EditRow(version, id, row);
  std::lock_guard lock(track_mutex);
  out.moved_to = SetDetachedVideoAside(store, out.after, out.video);
  return out;
}

}  // namespace uphill::internal
