#include "report/video_trials.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "internal/strict_json.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

std::string Num(double v) { return Printf("%.10g", v); }

// A ball at rest moves by the tracker's noise (hundredths of a mm): drawn on gnuplot's own range
// that noise would fill the figure as if it were motion. So the x axis spans at least
// kMinimumSpanMm, centred on the positions (and the model curve).
constexpr double kMinimumSpanMm = 5.0;
std::string MinimumXRange(const TrackFigureData& a) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto* points : {&a.measured, &a.curve})
    for (const auto& [t, x] : *points) lo = std::min(lo, x * 1e3), hi = std::max(hi, x * 1e3);
  if (!(hi >= lo) || hi - lo >= kMinimumSpanMm) return "";
  const double mid = 0.5 * (lo + hi);
  return "set yrange [" + Num(mid - kMinimumSpanMm / 2) + ":" + Num(mid + kMinimumSpanMm / 2) + "]\n";
}

}  // namespace

YComparison CompareY(double typed, double u_typed, double video, double u_video) {
  YComparison c;
  c.typed = typed;
  c.u_typed = u_typed;
  c.video = video;
  c.u_video = u_video;
  c.difference = typed - video;
  c.sigma = std::hypot(u_typed, u_video);
  // With both uncertainties 0 any difference is beyond 3σ.
  c.flagged = std::abs(c.difference) > 3.0 * c.sigma;
  return c;
}

std::optional<MotionMu> WeightedMotionMu(const std::vector<VideoTrial>& trials) {
  double sum_w = 0, sum_wx = 0;
  std::vector<std::pair<double, double>> used;  // (μ, u)
  for (const VideoTrial& t : trials) {
    if (!t.error.empty() || !t.fit_available || t.fitted != "mu" || !t.fit_value || !t.fit_value->u) continue;
    const double u = *t.fit_value->u;
    if (!(u > 0.0) || !std::isfinite(u) || !std::isfinite(t.fit_value->value)) continue;
    used.emplace_back(t.fit_value->value, u);
    sum_w += 1.0 / (u * u);
    sum_wx += t.fit_value->value / (u * u);
  }
  if (used.empty()) return std::nullopt;
  MotionMu m;
  m.trials = static_cast<int>(used.size());
  m.mu = sum_wx / sum_w;
  m.u = 1.0 / std::sqrt(sum_w);
  if (used.size() >= 2) {
    double chi2 = 0;
    for (const auto& [mu, u] : used) chi2 += (mu - m.mu) * (mu - m.mu) / (u * u);
    m.reduced_chi2 = chi2 / static_cast<double>(used.size() - 1);
  }
  return m;
}

std::vector<GnuplotFigure> TrackFigures(const TrackFigureData& a, const std::string& stem,
                                        const std::string& title_suffix) {
  std::vector<GnuplotFigure> figures;
  GnuplotFigure x;
  x.name = stem + kXVsT;
  x.title = (a.curve.empty() ? "Measured x(t), no motion fitted" : "Measured x(t) against the fitted model") + title_suffix;
  x.caption = "Each point is one video frame where the ball was found (x of its centre in the apparatus frame); " +
              (a.curve.empty() ? std::string("no model line: no motion was fitted (a ball at rest, or the fit was "
                                             "not available).")
                               : "the line is the model motion fitted to them (x0, t0 and " +
                                     (a.fitted == "mu" ? std::string("μ") : a.fitted.empty() ? "g or μ" : a.fitted) + ").");
  std::ostringstream data;
  data << "# t_s x_mm (every frame with the ball)\n";
  for (const auto& [t, xv] : a.measured) data << Num(t) << " " << Num(xv * 1e3) << "\n";
  data << "\n\n# t_s x_mm (fitted model)\n";
  for (const auto& [t, xv] : a.curve) data << Num(t) << " " << Num(xv * 1e3) << "\n";
  x.data = data.str();
  std::ostringstream plot;
  plot << "set xlabel 't (s)'\nset ylabel 'x, centre (mm)'\nset offsets graph 0.02, graph 0.02, graph 0.05, graph 0.05\n"
       << MinimumXRange(a) << "plot '" << x.name << ".dat' index 0 using 1:2 with points pt 7 ps 0.5 lc rgb '#1f4e79' title 'measured'";
  if (!a.curve.empty())
    plot << ", \\\n  '" << x.name << ".dat' index 1 using 1:2 with lines lw 2 lc rgb '#d62728' title 'fitted model'";
  x.plot = plot.str();
  figures.push_back(x);
  if (a.fit_available) {
    GnuplotFigure r;
    r.name = stem + kResiduals;
    r.title = "Residuals of the model fit" + title_suffix;
    r.caption = "Measured minus fitted x for every frame of the fit window, with the stated u_x as error bars. "
                "Structure (a trend, a wave) means the model misses something.";
    std::ostringstream rd;
    rd << "# t_s residual_mm u_x_mm\n";
    for (std::size_t i = 0; i < a.fit_t.size() && i < a.fit_residual.size(); ++i)
      rd << Num(a.fit_t[i]) << " " << Num(a.fit_residual[i] * 1e3) << " " << Num(a.u_x * 1e3) << "\n";
    r.data = rd.str();
    r.plot = "set xlabel 't (s)'\nset ylabel 'measured - fitted x (mm)'\n"
             "set offsets graph 0.02, graph 0.02, graph 0.1, graph 0.1\n"
             "plot 0 with lines lc rgb '#777777' notitle, \\\n  '" +
             r.name + ".dat' using 1:2:3 with yerrorbars pt 7 ps 0.5 lc rgb '#1f4e79' title sprintf('RMS %.3g mm', " +
             Num(a.rms_residual * 1e3) + ")";
    figures.push_back(r);
  }
  return figures;
}

}  // namespace uphill

namespace uphill {
namespace {

using nlohmann::json;

// The ranges a trial's numbers keep (the apparatus is a few metres long, a recording a few
// minutes; μ and g_eff are of order 1 and 10): far wider than any real trial, narrow enough that
// nothing derived from them (mm, squares, sums) overflows.
constexpr double kMaxLength = 1e3;     // m, |x| and its uncertainty
constexpr double kMaxTime = 1e6;       // s
constexpr double kMaxFitValue = 1e6;   // μ or g_eff (m/s²)
constexpr int kMaxCount = 1 << 30;     // rows, frames, degrees of freedom

json ValueJson(const std::optional<Estimate>& v) {
  if (!v) return nullptr;
  return {{"value", std::isfinite(v->value) ? json(v->value) : json(nullptr)}, {"u", v->u ? json(*v->u) : json(nullptr)}};
}

json PairsJson(const std::vector<std::pair<double, double>>& pairs) {
  json a = json::array();
  for (const auto& [t, x] : pairs) a.push_back({t, x});
  return a;
}

}  // namespace

json VideoTrialToJson(const VideoTrial& t, bool with_figure) {
  json j = {{"trial", t.trial},
            {"row", t.row},
            {"video", t.video},
            {"error", t.error},
            {"frames", t.frames},
            {"found", t.found},
            {"partial", t.partial},
            {"partial_reason", t.partial_reason},
            {"rest_x", ValueJson(t.rest)},
            {"no_rest", t.no_rest},
            {"release_x", ValueJson(t.release_x)},
            {"release_t", ValueJson(t.release_t)},
            {"fit_available", t.fit_available},
            {"fit_unavailable", t.fit_unavailable},
            {"fitted", t.fitted},
            {"fit_value", ValueJson(t.fit_value)},
            {"reduced_chi2", t.reduced_chi2},
            {"dof", t.dof},
            {"notes", t.notes}};
  json events = json::array();
  for (const TrackEvent& e : t.events)
    events.push_back({{"kind", e.kind}, {"t", ValueJson(e.t)}, {"x", ValueJson(e.x)}});
  j["events"] = events;
  if (with_figure) {
    const TrackFigureData& f = t.figure;
    j["figure"] = {{"measured", PairsJson(f.measured)}, {"curve", PairsJson(f.curve)}, {"fitted", f.fitted},
                   {"fit_available", f.fit_available}, {"fit_t", f.fit_t}, {"fit_residual", f.fit_residual},
                   {"u_x", f.u_x}, {"rms_residual", f.rms_residual}};
  }
  return j;
}

VideoTrial VideoTrialFromJson(const json& j) {
  const internal::StrictJson r(j, "");
  VideoTrial t;
  t.trial = r.Text("trial");
  t.row = r.Integer("row", 1, kMaxCount);
  t.video = r.Text("video");
  t.error = r.Text("error");
  t.frames = r.Integer("frames", 0, kMaxCount);
  t.found = r.Integer("found", 0, t.frames);
  t.partial = r.Bool("partial");
  t.partial_reason = r.Text("partial_reason");
  t.rest = r.Value("rest_x", kMaxLength, kMaxLength);
  t.no_rest = r.Text("no_rest");
  t.release_x = r.Value("release_x", kMaxLength, kMaxLength);
  t.release_t = r.Value("release_t", kMaxTime, kMaxTime);
  t.fit_available = r.Bool("fit_available");
  t.fit_unavailable = r.Text("fit_unavailable");
  t.fitted = r.OneOf("fitted", {"", "g", "mu"});
  t.fit_value = r.Value("fit_value", kMaxFitValue, kMaxFitValue);
  t.reduced_chi2 = r.Number("reduced_chi2", 0, std::numeric_limits<double>::max());
  t.dof = r.Integer("dof", 0, kMaxCount);
  t.notes = r.Texts("notes");
  r.ForEach("events", [&](const internal::StrictJson& e) {
    TrackEvent ev;
    ev.kind = e.Text("kind");
    ev.t = e.Value("t", kMaxTime, kMaxTime).value_or(Estimate{});
    ev.x = e.Value("x", kMaxLength, kMaxLength).value_or(Estimate{});
    t.events.push_back(ev);
  });
  if (j.contains("figure")) {
    const internal::StrictJson f = r.Object("figure");
    t.figure.measured = f.Pairs("measured", kMaxTime, kMaxLength);
    t.figure.curve = f.Pairs("curve", kMaxTime, kMaxLength);
    t.figure.fitted = f.OneOf("fitted", {"", "g", "mu"});
    t.figure.fit_available = f.Bool("fit_available");
    t.figure.fit_t = f.Numbers("fit_t", kMaxTime);
    t.figure.fit_residual = f.Numbers("fit_residual", kMaxLength);
    t.figure.u_x = f.Number("u_x", 0, kMaxLength);
    t.figure.rms_residual = f.Number("rms_residual", 0, kMaxLength);
  }
  return t;
}

}  // namespace uphill
