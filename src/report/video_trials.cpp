#include "report/video_trials.hpp"

#include <cmath>
#include <sstream>

#include "model/number_text.hpp"

namespace uphill {
namespace {

std::string Num(double v) { return Printf("%.10g", v); }

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
  x.title = "Measured x(t) against the fitted model" + title_suffix;
  x.caption = "Each point is one video frame where the ball was found (x of its centre in the apparatus frame); "
              "the line is the model motion fitted to them (x0, t0 and " +
              (a.fitted.empty() ? std::string("g or mu") : a.fitted) + ").";
  std::ostringstream data;
  data << "# t_s x_mm (every frame with the ball)\n";
  for (const auto& [t, xv] : a.measured) data << Num(t) << " " << Num(xv * 1e3) << "\n";
  data << "\n\n# t_s x_mm (fitted model)\n";
  for (const auto& [t, xv] : a.curve) data << Num(t) << " " << Num(xv * 1e3) << "\n";
  x.data = data.str();
  std::ostringstream plot;
  plot << "set xlabel 't (s)'\nset ylabel 'x, centre (mm)'\nset offsets graph 0.02, graph 0.02, graph 0.05, graph 0.05\n"
       << "plot '" << x.name << ".dat' index 0 using 1:2 with points pt 7 ps 0.5 lc rgb '#1f4e79' title 'measured'";
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

json ValueJson(const std::optional<MeasuredValue>& v) {
  if (!v) return nullptr;
  return {{"value", std::isfinite(v->value) ? json(v->value) : json(nullptr)}, {"u", v->u ? json(*v->u) : json(nullptr)}};
}

std::optional<MeasuredValue> ValueFrom(const json& j) {
  if (j.is_null()) return std::nullopt;
  MeasuredValue v;
  v.value = j.at("value").is_null() ? std::nan("") : j.at("value").get<double>();
  if (!j.at("u").is_null()) v.u = j.at("u").get<double>();
  return v;
}

json PairsJson(const std::vector<std::pair<double, double>>& pairs) {
  json a = json::array();
  for (const auto& [t, x] : pairs) a.push_back({t, x});
  return a;
}

std::vector<std::pair<double, double>> PairsFrom(const json& j) {
  std::vector<std::pair<double, double>> out;
  for (const json& p : j) out.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
  return out;
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
  for (const VideoTrialEvent& e : t.events)
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
  VideoTrial t;
  t.trial = j.at("trial").get<std::string>();
  t.row = j.at("row").get<int>();
  t.video = j.at("video").get<std::string>();
  t.error = j.at("error").get<std::string>();
  t.frames = j.at("frames").get<int>();
  t.found = j.at("found").get<int>();
  t.partial = j.at("partial").get<bool>();
  t.partial_reason = j.at("partial_reason").get<std::string>();
  t.rest = ValueFrom(j.at("rest_x"));
  t.no_rest = j.at("no_rest").get<std::string>();
  t.release_x = ValueFrom(j.at("release_x"));
  t.release_t = ValueFrom(j.at("release_t"));
  t.fit_available = j.at("fit_available").get<bool>();
  t.fit_unavailable = j.at("fit_unavailable").get<std::string>();
  t.fitted = j.at("fitted").get<std::string>();
  t.fit_value = ValueFrom(j.at("fit_value"));
  t.reduced_chi2 = j.at("reduced_chi2").get<double>();
  t.dof = j.at("dof").get<int>();
  t.notes = j.at("notes").get<std::vector<std::string>>();
  for (const json& e : j.at("events")) {
    VideoTrialEvent ev;
    ev.kind = e.at("kind").get<std::string>();
    if (auto v = ValueFrom(e.at("t"))) ev.t = *v;
    if (auto v = ValueFrom(e.at("x"))) ev.x = *v;
    t.events.push_back(ev);
  }
  if (j.contains("figure")) {
    const json& f = j.at("figure");
    t.figure.measured = PairsFrom(f.at("measured"));
    t.figure.curve = PairsFrom(f.at("curve"));
    t.figure.fitted = f.at("fitted").get<std::string>();
    t.figure.fit_available = f.at("fit_available").get<bool>();
    t.figure.fit_t = f.at("fit_t").get<std::vector<double>>();
    t.figure.fit_residual = f.at("fit_residual").get<std::vector<double>>();
    t.figure.u_x = f.at("u_x").get<double>();
    t.figure.rms_residual = f.at("rms_residual").get<double>();
  }
  return t;
}

}  // namespace uphill
