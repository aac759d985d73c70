#include "app/paper_figures.hpp"

#include <boost/math/quadrature/tanh_sinh.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "io/atomic_file.hpp"
#include "io/experiment.hpp"
#include "io/output_paths.hpp"
#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "report/analysis.hpp"
#include "report/analysis_figures.hpp"
#include "report/document.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill {
namespace {


namespace fs = std::filesystem;
constexpr double kDeg = M_PI / 180.0, kG = 9.80665;

std::string Line(std::initializer_list<double> values) {
  std::string out;
  char buf[40];
  for (double v : values) {
    std::snprintf(buf, sizeof buf, "%s%.10g", out.empty() ? "" : " ", v);
    out += buf;
  }
  return out + "\n";
}

GnuplotFigure PotentialFigure() {
  // Paper FIG. 4: U(x) = m·g·z(x) for several b/a, α = 30°, θ = 10°, a = 20 mm.
  GnuplotFigure f{"fig_potential", "U(x) for several b/a (alpha = 30 deg, theta = 10 deg)",
                          "Potential energy U/(m g a) = z/a of the centre against x/a, spheroid a = 20 mm, "
                          "b/a = 0.5, 1, 1.6, 2, 3; each curve ends at its fall-off x_max; the maximum is X.",
                          "", "set xlabel 'x / a'\nset ylabel 'U / (m g a) = z / a'\nset key top right\nset grid\nplot "};
  const double a = 0.02;
  const Rails rails = Rails::FromAngles(10 * kDeg, 30 * kDeg);
  int k = 0;
  for (double ratio : {0.5, 1.0, 1.6, 2.0, 3.0}) {
    const Scene s(Body::Spheroid(a, ratio * a), rails);
    f.data += "# b/a = " + std::to_string(ratio) + "\n# x/a z/a\n";
    const double lo = 0.0, hi = s.x_max();
    for (int i = 0; i <= 400; ++i) {
      const double x = lo + (hi - lo) * i / 400.0;
      f.data += Line({x / a, s.At(x).z / a});
    }
    f.data += "\n\n";
    char title[32];
    std::snprintf(title, sizeof title, "b/a = %g", ratio);
    f.plot += std::string(k ? ", " : "") + "'fig_potential.dat' index " + std::to_string(k) +
              " with lines lw 2 title '" + title + "'";
    ++k;
  }
  f.plot += "\n";
  return f;
}

// X/a against an angle, for b/a = 1, 1.6, 2.
GnuplotFigure XFigure(bool against_phi) {
  const std::string name = against_phi ? "fig_x_vs_phi" : "fig_x_vs_theta";
  GnuplotFigure f{name,
                          against_phi ? "X against phi (theta = 1 deg)" : "X against theta (phi = 30 deg)",
                          against_phi ? "Unstable equilibrium X/a against the 3-D half angle phi between the rails "
                                        "(tan phi = tan(alpha/2) cos theta), theta = 1 deg."
                                      : "Unstable equilibrium X/a against the inclination theta at fixed 3-D "
                                        "half angle phi = 30 deg.",
                          "",
                          std::string("set xlabel '") + (against_phi ? "phi" : "theta") +
                              " [deg]'\nset ylabel 'X / a'\nset logscale y\nset format y '10^{%L}'\nset key top right\nset grid\nplot "};
  const double a = 0.02;
  int k = 0;
  for (double ratio : {1.0, 1.6, 2.0}) {
    f.data += "# b/a = " + std::to_string(ratio) + "\n# angle_deg X/a\n";
    for (int i = 1; i < 179; ++i) {
      const double angle = 0.5 * i;  // 0.5 … 89 deg
      const double theta = against_phi ? 1 * kDeg : angle * kDeg;
      const double phi = against_phi ? angle * kDeg : 30 * kDeg;
      const double alpha = 2 * std::atan(std::tan(phi) / std::cos(theta));
      if (!(alpha < M_PI)) continue;
      const Scene s(Body::Spheroid(a, ratio * a), Rails::FromAngles(theta, alpha));
      f.data += Line({angle, *s.x_eq() / a});
    }
    f.data += "\n\n";
    char title[32];
    std::snprintf(title, sizeof title, "b/a = %g", ratio);
    f.plot += std::string(k ? ", " : "") + "'" + name + ".dat' index " + std::to_string(k) +
              " with lines lw 2 title '" + title + "'";
    ++k;
  }
  f.plot += "\n";
  return f;
}

// Sphere, θ = 0, φ = 60° (α = 120°), R = 20 mm, released at rest at s = 0.1 R.
struct SphereCase {
  double R = 0.02;
  Scene scene{Body::Sphere(0.02), Rails::FromAngles(0.0, 120 * kDeg)};
  double s = 0.002;
};

// The paper's eq. 8: the clock started at s with the energy of a body at rest at x = 0 (the
// separatrix): t_paper(x) = ∫_s^x dx/ẋ_sep, ẋ_sep = v_sep/sqrt(1 + z'²), ½K v_sep² = g(R − z).
double PaperTime(const SphereCase& c, double x) {
  auto xdot = [&](double xi) {
    const PathPoint p = c.scene.At(xi);
    const double v = std::sqrt(2 * kG * (c.R - p.z) / c.scene.KineticFactor(xi));
    return v / std::sqrt(1 + p.dzdx * p.dzdx);
  };
  boost::math::quadrature::tanh_sinh<double> ts;
  return ts.integrate([&](double xi) { return 1.0 / xdot(xi); }, c.s, x);
}
double PaperSpeed(const SphereCase& c, double x) {
  return std::sqrt(2 * kG * (c.R - c.scene.At(x).z) / c.scene.KineticFactor(x));
}

std::vector<GnuplotFigure> SphereFigures() {
  SphereCase c;
  const Motion m(c.scene, c.s);
  const double t_end = m.end_time();
  std::string traj = "# release at rest at s = 0.1 R (uphill)\n# t_s x_mm z_mm v vx vz (m/s)\n";
  for (int i = 0; i <= 300; ++i) {
    const MotionSample p = m.At(t_end * i / 300.0);
    traj += Line({p.t, p.x * 1e3, p.z * 1e3, p.v, p.vx, p.vz});
  }
  std::string paper = "\n\n# paper eq. 8 / vc (separatrix, clock started at s)\n# t_s x_mm v_m/s\n";
  for (int i = 1; i <= 300; ++i) {
    const double x = c.s + (0.999 * c.scene.x_max() - c.s) * i / 300.0;
    paper += Line({PaperTime(c, x), x * 1e3, PaperSpeed(c, x)});
  }
  const std::string caption_tail =
      " Sphere R = 20 mm, theta = 0, phi = 60 deg, released at rest at s = 0.1 R; ends at the fall-off x_max = "
      "R/sin(alpha/2). Dashed: the paper's eq. 8 (and its speed), which is the separatrix (energy of a body at "
      "rest at x = 0, clock started at s), not the release from rest (docs/physics.md, "
      "\"Sphere at θ = 0\").";
  std::vector<GnuplotFigure> out;
  out.push_back({"fig_sphere_xz_t", "Sphere: x(t) and z(t)", "Position x and height z of the centre." + caption_tail,
                 traj + paper,
                 "set xlabel 't [s]'\nset ylabel 'x, z [mm]'\nset key top left\nset grid\n"
                 "plot 'fig_sphere_xz_t.dat' index 0 using 1:2 with lines lw 2 title 'x(t), release at s (uphill)', "
                 "'' index 0 using 1:3 with lines lw 2 title 'z(t)', "
                 "'' index 1 using 1:2 with lines dt 2 lw 2 title 'x(t), paper eq. 8 (separatrix)'\n"});
  out.push_back({"fig_sphere_speed_x", "Sphere: speeds against x", "Speed of the centre and its components." + caption_tail,
                 traj + paper,
                 "set xlabel 'x [mm]'\nset ylabel 'speed [m/s]'\nset key top left\nset grid\n"
                 "plot 'fig_sphere_speed_x.dat' index 0 using 2:4 with lines lw 2 title 'v_C', "
                 "'' index 0 using 2:5 with lines lw 2 title 'v_{Cx}', "
                 "'' index 0 using 2:(-$6) with lines lw 2 title '-v_{Cz}', "
                 "'' index 1 using 2:3 with lines dt 2 lw 2 title 'v_C, paper (separatrix)'\n"});
  out.push_back({"fig_sphere_speed_t", "Sphere: speeds against t", "Speed of the centre and its components." + caption_tail,
                 traj + paper,
                 "set xlabel 't [s]'\nset ylabel 'speed [m/s]'\nset key top left\nset grid\n"
                 "plot 'fig_sphere_speed_t.dat' index 0 using 1:4 with lines lw 2 title 'v_C', "
                 "'' index 0 using 1:5 with lines lw 2 title 'v_{Cx}', "
                 "'' index 0 using 1:(-$6) with lines lw 2 title '-v_{Cz}', "
                 "'' index 1 using 1:3 with lines dt 2 lw 2 title 'v_C, paper eq. 8 clock (separatrix)'\n"});
  return out;
}

// The paper's two experiment plots, from the sample experiments (data/README.md): Y against X
// with the fits, drawn by the report layer into DIR/<series>/.
void ExperimentFigures(const std::string& data_dir, const std::string& dir, Document* gallery,
                       std::vector<std::string>* written) {
  const struct {
    const char* folder;
    const char* title;
  } series[] = {{"series1-fixed-D", "Experiment 1 (sample data): D fixed, L varied"},
                {"series2-fixed-L", "Experiment 2 (sample data): L fixed, D varied"}};
  for (const auto& s : series) {
    const Experiment experiment = LoadExperiment((fs::path(data_dir) / s.folder).string());
    AnalysisOptions options;
    options.mc_trials = 10000;
    const ExperimentAnalysis analysis = AnalyseExperiment(experiment, options);
    const fs::path sub = fs::path(dir) / s.folder;
    OutputPaths::CreateFolders(sub.string());
    for (const GnuplotFigure& f : AnalysisFigures(analysis)) {
      if (f.name == "fit_residuals") continue;
      RenderFigure(f, sub.string());
      gallery->Figure(std::string(s.folder) + "/" + f.name, std::string(s.title) + ": " + f.title, f.caption);
      written->push_back(sub.string() + "/" + f.name + ".{svg,png}");
    }
  }
}

}  // namespace

std::vector<std::string> WritePaperFigures(const std::string& dir, const std::string& data_dir) {
  std::vector<std::string> written;
  OutputPaths outputs;  // checked before any work
  outputs.CheckFolder(dir, "-o", {"index.html"});
  OutputPaths::CreateFolders(dir);
  std::vector<GnuplotFigure> figures{PotentialFigure(), XFigure(true), XFigure(false)};
  for (auto& f : SphereFigures()) figures.push_back(std::move(f));
  Document gallery;
  gallery.title = "The seed paper's figures, redrawn by uphill";
  gallery.Paragraph("Each figure is drawn by gnuplot from the script (.gp) and data (.dat) kept beside its SVG "
                    "and PNG in this folder. Where docs/physics.md (\"The seed paper's errors\") shows the "
                    "paper's formula to be wrong, the "
                    "corrected physics is drawn and the paper's curve is added, labelled as such.");
  for (const auto& f : figures) {
    RenderFigure(f, dir);
    gallery.Figure(f.name, f.title, f.caption);
    written.push_back(dir + "/" + f.name + ".{svg,png}");
  }
  if (data_dir.empty()) {
    gallery.Paragraph("The experiment plots need the sample experiments (data/series1-fixed-D, "
                      "data/series2-fixed-L): give --data.");
  } else {
    ExperimentFigures(data_dir, dir, &gallery, &written);
  }
  WriteFileAtomically((fs::path(dir) / "index.html").string(), RenderHtml(gallery, dir));
  written.push_back(dir + "/index.html");
  return written;
}

}  // namespace uphill
