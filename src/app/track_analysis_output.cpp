#include "app/track_analysis_output.hpp"

#include <filesystem>
#include <sstream>

#include "io/atomic_file.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

constexpr const char* kAnalysisFile = "track_analysis.json";
constexpr const char* kFigureStem = "track";  // track_x_vs_t, track_residuals (report/video_trials.hpp)

nlohmann::json Optional(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json EventJson(const std::optional<TrackEvent>& e) {
  if (!e) return nullptr;
  return {{"kind", e->kind}, {"t", Finite(e->t.value)}, {"u_t", Optional(e->t.u)}, {"x", Finite(e->x.value)},
          {"u_x", Optional(e->x.u)}, {"method", e->method}};
}

// "123.456 ± 0.012" with the uncertainty's scale deciding the digits.
std::string WithU(double value, const std::optional<double>& u, double factor, const char* unit) {
  if (!std::isfinite(value)) return "never";
  std::string text = Printf("%.6f", value * factor);
  if (u) text = Printf("%.6f", value * factor) + " ± " + Printf("%.2g", *u * factor);
  return text + " " + unit;
}

}  // namespace

std::string TrackAnalysisTable(const TrackAnalysis& a) {
  std::ostringstream out;
  out << "track " << a.source << ": " << a.found << " of " << a.frames << " frames with the ball";
  if (a.frame_interval > 0) out << ", " << Printf("%.4g", 1.0 / a.frame_interval) << " frames/s";
  out << "; u_x = " << Printf("%.3g", a.options.u_x * 1e3) << " mm";
  if (a.scatter_at_rest) out << " (scatter at rest " << Printf("%.3g", *a.scatter_at_rest * 1e3) << " mm)";
  out << "\n";
  out << "direction: " << (a.direction > 0 ? "up (away from O)" : a.direction < 0 ? "down (toward O)" : "none (never moves)")
      << "\n";
  out << "events                 t [s]                       x [mm]                     how\n";
  const auto row = [&](const std::optional<TrackEvent>& e) {
    if (!e) return;
    char line[512];
    std::snprintf(line, sizeof line, "  %-20s %-27s %-26s %s\n", e->kind.c_str(),
                  WithU(e->t.value, e->t.u, 1.0, "s").c_str(), WithU(e->x.value, e->x.u, 1e3, "mm").c_str(),
                  e->method.c_str());
    out << line;
  };
  row(a.release);
  for (const auto& e : a.turning_points) row(e);
  row(a.rest);
  row(a.fall_off);
  row(a.reaches_o);
  if (a.rest) out << "  measured Y (rest position) = " << WithU(a.rest->x.value, a.rest->x.u, 1e3, "mm") << "\n";
  const TrackFit& f = a.fit;
  if (!f.available) {
    out << "model fit: not available: " << f.unavailable << "\n";
  } else {
    out << "model fit (x0, t0, " << f.fitted << "; Huber loss at " << Printf("%.3g", a.options.huber_sigmas)
        << " u_x), " << f.t.size() << " frames:\n";
    out << "  parameter      value            se (from u_x)    se (scaled by sqrt(chi2/dof))  statistical  systematic  "
           "u (to quote)\n";
    const auto text = [](const std::optional<double>& v, double factor) {
      return v ? Printf("%.3g", *v * factor) : std::string("-");
    };
    for (const auto& p : f.parameters) {
      const double factor = p.unit == "m" ? 1e3 : 1.0;
      const std::string unit = p.unit == "m" ? "mm" : p.unit.empty() ? "1" : p.unit;
      char line[320];
      std::snprintf(line, sizeof line, "  %-6s %-7s %-16s %-16s %-30s %-12s %-11s %s\n", p.name.c_str(),
                    ("[" + unit + "]").c_str(), Printf("%.8g", p.value * factor).c_str(), text(p.se, factor).c_str(),
                    text(p.se_scaled, factor).c_str(), text(p.se_statistical, factor).c_str(),
                    text(p.se_systematic, factor).c_str(), text(p.u, factor).c_str());
      out << line;
    }
    out << "  statistical: from the residuals (lag-1 autocorrelation " << Printf("%.2f", f.residual_lag1)
        << "); systematic: " << Printf("%.3g", a.options.fit_systematic_scale) << " x (the tracker's "
        << Printf("%.3g", a.options.tracker_floor_px) << " px + " << Printf("%.3g", a.options.tracker_blur)
        << " x (px moved per frame)) at "
        << Printf("%.3g", f.metres_per_pixel * 1e3) << " mm/px, averaged over its correlation length along the path\n";
    out << "  chi2 = " << Printf("%.4g", f.chi2) << ", dof = " << f.dof << ", chi2/dof = " << Printf("%.4g", f.reduced_chi2)
        << ", RMS residual = " << Printf("%.3g", f.rms_residual * 1e3) << " mm\n";
    for (const auto& e : f.model_events)
      out << "  model: " << e.kind << " at t = " << WithU(e.t.value, e.t.u, 1.0, "s")
          << ", x = " << WithU(e.x.value, e.x.u, 1e3, "mm") << "\n";
  }
  for (const auto& note : f.notes) out << "  * " << note << "\n";
  for (const auto& note : a.notes) out << "* " << note << "\n";
  return out.str();
}

nlohmann::json TrackAnalysisJson(const TrackAnalysis& a) {
  nlohmann::json j;
  j["format"] = "uphill-track-analysis/1";
  j["source"] = a.source;
  j["frames"] = a.frames;
  j["found"] = a.found;
  j["frame_interval"] = a.frame_interval;
  j["u_x"] = a.options.u_x;
  j["band_sigmas"] = a.options.band_sigmas;
  j["tracker_floor_px"] = a.options.tracker_floor_px;
  j["tracker_blur"] = a.options.tracker_blur;
  j["fit_systematic_scale"] = a.options.fit_systematic_scale;
  j["g"] = a.options.g;
  j["scatter_at_rest"] = Optional(a.scatter_at_rest);
  j["direction"] = a.direction;
  j["release"] = EventJson(a.release);
  j["turning_points"] = nlohmann::json::array();
  for (const auto& e : a.turning_points) j["turning_points"].push_back(EventJson(e));
  j["rest"] = EventJson(a.rest);
  j["y_measured"] = a.rest ? nlohmann::json(a.rest->x.value) : nlohmann::json(nullptr);
  j["u_y_measured"] = a.rest ? Optional(a.rest->x.u) : nlohmann::json(nullptr);
  j["fall_off"] = EventJson(a.fall_off);
  j["reaches_o"] = EventJson(a.reaches_o);
  const TrackFit& f = a.fit;
  nlohmann::json fit;
  fit["available"] = f.available;
  if (!f.available) fit["unavailable"] = f.unavailable;
  fit["fitted"] = f.fitted;
  fit["parameters"] = nlohmann::json::object();
  for (const auto& p : f.parameters)
    fit["parameters"][p.name] = {{"value", p.value},
                                 {"se", Optional(p.se)},
                                 {"se_scaled", Optional(p.se_scaled)},
                                 {"se_statistical", Optional(p.se_statistical)},
                                 {"se_systematic", Optional(p.se_systematic)},
                                 {"u", Optional(p.u)},
                                 {"unit", p.unit}};
  if (f.covariance) {
    nlohmann::json c = nlohmann::json::array(), r = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) {
      nlohmann::json crow = nlohmann::json::array(), rrow = nlohmann::json::array();
      for (int k = 0; k < 3; ++k) {
        crow.push_back((*f.covariance)(i, k));
        rrow.push_back((*f.covariance)(i, k) / std::sqrt((*f.covariance)(i, i) * (*f.covariance)(k, k)));
      }
      c.push_back(crow);
      r.push_back(rrow);
    }
    fit["covariance"] = c;
    fit["correlation"] = r;
  } else {
    fit["covariance"] = nullptr;
    fit["correlation"] = nullptr;
  }
  if (f.available) {
    fit["chi2"] = f.chi2;
    fit["dof"] = f.dof;
    fit["reduced_chi2"] = f.reduced_chi2;
    fit["rms_residual"] = f.rms_residual;
    fit["residual_lag1"] = f.residual_lag1;
    fit["metres_per_pixel"] = f.metres_per_pixel;
    fit["n"] = f.t.size();
    fit["iterations"] = f.iterations;
    fit["termination"] = f.termination;
  }
  fit["model_events"] = nlohmann::json::array();
  for (const auto& e : f.model_events) fit["model_events"].push_back(EventJson(e));
  fit["frames"] = nlohmann::json::array();
  for (std::size_t i = 0; i < f.t.size(); ++i)
    fit["frames"].push_back({{"row", f.rows[i]},
                             {"t", f.t[i]},
                             {"x", f.measured[i]},
                             {"predicted", f.predicted[i]},
                             {"residual", f.measured[i] - f.predicted[i]},
                             {"u_systematic", i < f.systematic.size() ? nlohmann::json(f.systematic[i]) : nullptr}});
  fit["notes"] = f.notes;
  j["fit"] = fit;
  j["notes"] = a.notes;
  return j;
}

TrackFigureData TrackFigureDataOf(const TrackAnalysis& a) {
  TrackFigureData d;
  d.measured = a.measured;
  d.curve = a.fit.curve;
  d.fitted = a.fit.fitted;
  d.fit_available = a.fit.available;
  d.fit_t = a.fit.t;
  for (std::size_t i = 0; i < a.fit.t.size(); ++i) d.fit_residual.push_back(a.fit.measured[i] - a.fit.predicted[i]);
  d.u_x = a.options.u_x;
  d.rms_residual = a.fit.rms_residual;
  return d;
}

std::vector<GnuplotFigure> TrackAnalysisFigures(const TrackAnalysis& a) {
  return TrackFigures(TrackFigureDataOf(a), kFigureStem);
}

std::vector<std::string> TrackAnalysisFiles() {
  std::vector<std::string> files = {kAnalysisFile};
  for (const std::string& name : {std::string(kFigureStem) + "_x_vs_t", std::string(kFigureStem) + "_residuals"})
    for (std::string& file : FigureFiles(name)) files.push_back(std::move(file));
  return files;
}

void WriteTrackAnalysis(const TrackAnalysis& analysis, const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw EnvironmentError(directory + ": cannot create the folder: " + ec.message());
  WriteFileAtomically((std::filesystem::path(directory) / kAnalysisFile).string(),
                          TrackAnalysisJson(analysis).dump(2) + "\n");
  for (const auto& figure : TrackAnalysisFigures(analysis)) RenderFigure(figure, directory);
}

}  // namespace uphill
