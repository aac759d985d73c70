#include "report/video_report.hpp"

#include <cmath>

#include "model/number_text.hpp"

namespace uphill {
namespace {

std::string Mm(double m) { return Printf("%.2f", m * 1e3); }
std::string MmU(const std::optional<Estimate>& v) {
  if (!v || !std::isfinite(v->value)) return "-";
  return Printf("%.2f", v->value * 1e3) + (v->u ? Printf(" ± %.2g", *v->u * 1e3) : "");
}
std::string SecondsU(const std::optional<Estimate>& v) {
  if (!v || !std::isfinite(v->value)) return "-";
  return Printf("%.4f", v->value) + (v->u ? Printf(" ± %.2g", *v->u) : "");
}
std::string FitText(const VideoTrial& t) {
  if (!t.fit_available || !t.fit_value) return "-";
  const std::string name = t.fitted == "mu" ? "μ = " : "g_eff = ";
  const char* format = t.fitted == "mu" ? "%.5f" : "%.4f";
  return name + Printf(format, t.fit_value->value) + (t.fit_value->u ? " ± " + Printf("%.2g", *t.fit_value->u) : "") +
         (t.fitted == "mu" ? "" : " m/s2");
}

std::string Stem(std::size_t i) {
  const std::string n = std::to_string(i + 1);
  return "video_" + std::string(n.size() < 2 ? 2 - n.size() : 0, '0') + n;
}

const ExperimentRow* RowOf(const ExperimentAnalysis& a, int row) {
  for (const ExperimentRow& r : a.experiment->rows)
    if (r.row == row) return &r;
  return nullptr;
}

}  // namespace

void AddVideoSections(const ExperimentAnalysis& a, bool with_figures, Document* d) {
  if (a.video_trials.empty()) return;
  d->Heading("Rest positions from the videos");
  d->Paragraph("Each trial's recording is tracked and its track analysed (docs/analyse-track.md); the final rest "
               "of the body is a measured Y. Where Y was typed too, the typed Y is the one fitted and the two are "
               "compared: a difference beyond 3 combined standard uncertainties is flagged.");
  Table rest{{"trial", "video", "Y typed (mm)", "Y from video (mm)", "typed − video (σ)", "flag"}, {}};
  int flagged = 0;
  for (const VideoTrial& t : a.video_trials) {
    const ExperimentRow* row = RowOf(a, t.row);
    std::vector<std::string> cells = {t.trial, t.video};
    const bool typed = row && row->y_typed;
    cells.push_back(typed ? Printf("%.2f", row->Y.value * 1e3) + Printf(" ± %.2g", row->Y.u * 1e3) : "-");
    cells.push_back(!t.error.empty() ? "failed (below)" : t.rest ? MmU(t.rest) : t.no_rest);
    if (typed && t.error.empty() && t.rest && t.rest->u) {
      const YComparison c = CompareY(row->Y.value, row->Y.u, t.rest->value, *t.rest->u);
      cells.push_back(c.sigma > 0 ? Printf("%+.2f", c.difference / c.sigma) : Printf("%+.3f mm", c.difference * 1e3));
      cells.push_back(c.flagged ? "differ beyond 3σ" : "");
      flagged += c.flagged;
    } else {
      cells.push_back("-");
      cells.push_back(typed ? "" : "Y from the video");
    }
    rest.rows.push_back(cells);
  }
  d->AddTable(rest);
  if (flagged > 0)
    d->Paragraph(std::to_string(flagged) + " trial(s) have a typed Y and a video Y that differ by more than 3σ: "
                 "check the typed value, the scene calibration, or whether the body was disturbed.");

  d->Heading("Motion fits");
  d->Paragraph("The model motion released from rest at x0 at time t0 fitted to each track's x(t) (vision's "
               "analyse-track): with fit = mu the rolling-resistance coefficient μ at the stated g, with fit = g an "
               "effective g (μ = 0). Uncertainties are analyse-track's u: the residuals' scatter and the tracker's systematic "
               "error added in quadrature (docs/analyse-track.md, \"Accuracy\").");
  Table fits{{"trial", "x0 (mm)", "t0 (s)", "fit", "χ²/ν", "frames (found)", "events", "notes"}, {}};
  for (const VideoTrial& t : a.video_trials) {
    if (!t.error.empty()) continue;
    std::string events;
    for (const TrackEvent& e : t.events)
      events += (events.empty() ? "" : "; ") + e.kind + (std::isfinite(e.x.value) ? " at " + Mm(e.x.value) + " mm" : "");
    std::string notes = t.fit_available ? "" : t.fit_unavailable;
    if (t.partial) notes += (notes.empty() ? "" : "; ") + ("partial track: " + t.partial_reason);
    fits.rows.push_back({t.trial, MmU(t.release_x), SecondsU(t.release_t), FitText(t),
                         t.fit_available ? Printf("%.2f", t.reduced_chi2) : "-",
                         std::to_string(t.frames) + " (" + std::to_string(t.found) + ")", events, notes});
  }
  d->AddTable(fits);

  d->Heading("Friction cross-check");
  const std::optional<MotionMu> motion = WeightedMotionMu(a.video_trials);
  const FitOutcome* friction = a.Fit("friction");
  std::string text;
  if (motion) {
    text = "Rolling-resistance coefficient μ from the motions: " + Printf("%.5f", motion->mu) + Printf(" ± %.2g", motion->u) + " (weighted mean of " +
           std::to_string(motion->trials) + " trials";
    text += motion->reduced_chi2 ? Printf(", χ²/ν %.2f). ", *motion->reduced_chi2) : std::string("). ");
  } else {
    text = "No trial's motion fit gives μ (set \"video_analysis\": {\"fit\": \"mu\"} in experiment.json to fit it). ";
  }
  if (friction && friction->report) {
    const FitReport& r = *friction->report;
    const double mu = r.Parameter("mu").value;
    const auto se = r.StandardError("mu", r.primary_scaling);
    text += "μ from the rest positions (the friction fit of Y against the settings): " + Printf("%.5f", mu) +
            (se ? " ± " + Printf("%.2g", *se) : "") + ". ";
    if (motion && se) {
      const double sigma = std::hypot(motion->u, *se);
      text += Printf("They differ by %.2f combined standard uncertainties", (motion->mu - mu) / sigma) +
              (std::abs(motion->mu - mu) > 3 * sigma ? std::string(": the friction model does not describe both the "
                                                                   "motion and the rest (beyond 3σ).")
                                                     : std::string(": consistent."));
    }
  } else {
    text += "The friction fit of the rest positions is not available" +
            (friction ? " (" + friction->unavailable + ")." : std::string("."));
  }
  d->Paragraph(text);

  std::vector<std::string> errors;
  for (const VideoTrial& t : a.video_trials)
    if (!t.error.empty()) errors.push_back(t.error);
  if (!errors.empty()) {
    d->Heading("Videos that could not be analysed");
    d->List(errors);
  }
  if (with_figures) {
    d->Heading("Figures of the videos");
    for (const GnuplotFigure& f : VideoTrialFigures(a)) d->Figure(f.name, f.title, f.caption);
  }
}

std::vector<GnuplotFigure> VideoTrialFigures(const VideoTrial& t, std::size_t index) {
  if (!t.error.empty() || t.figure.measured.empty()) return {};
  return TrackFigures(t.figure, Stem(index), " (trial " + t.trial + ")");
}

std::vector<std::string> VideoTrialFigureNames(std::size_t index) {
  return {Stem(index) + kXVsT, Stem(index) + kResiduals};
}

std::vector<GnuplotFigure> VideoTrialFigures(const ExperimentAnalysis& a) {
  std::vector<GnuplotFigure> out;
  for (std::size_t i = 0; i < a.video_trials.size(); ++i)
    for (GnuplotFigure& f : VideoTrialFigures(a.video_trials[i], i)) out.push_back(std::move(f));
  return out;
}

void AddVideoJson(const ExperimentAnalysis& a, nlohmann::ordered_json* j) {
  if (a.video_trials.empty()) return;
  nlohmann::ordered_json trials = nlohmann::ordered_json::array();
  for (const VideoTrial& t : a.video_trials)
    trials.push_back(nlohmann::ordered_json::parse(VideoTrialToJson(t, false).dump()));
  (*j)["video_trials"] = trials;
  if (const auto m = WeightedMotionMu(a.video_trials)) {
    (*j)["motion_mu"] = {{"mu", m->mu}, {"u", m->u}, {"trials", m->trials},
                         {"reduced_chi2", m->reduced_chi2 ? nlohmann::ordered_json(*m->reduced_chi2) : nlohmann::ordered_json(nullptr)}};
  } else {
    (*j)["motion_mu"] = nullptr;
  }
}

}  // namespace uphill
