// make_samples: writes the sample experiments in data/ (format uphill-experiment/1).
//
// The samples are synthetic, generated from the model so that the analysis has a known answer:
// the lab spheroid (2 × 1.25 × 1.25 in: a = 15.875 mm, b = 25.4 mm) on line rails, H = 300 mm,
// rolling resistance μ = 0.05 (slope threshold, docs/physics.md
// "Rolling resistance"), so the true farthest rest position
// is Y = x_rest(μ) of the true setting. Recorded L, H, D and Y carry Gaussian noise of the stated
// standard uncertainties (seeded: the files are reproducible).
//
// Why not the paper's numbers: with tanθ = H/L, x_eq/L = (2b/D)/sqrt(1 + (a·D/(2b·H))²) depends
// only on D/H. The paper's D = 45 mm gives X = 1.128·L, beyond the crossbar and within 0.12 % of
// the fall-off, for every L, so no measurement could be taken there. Series 1 therefore fixes
// D = 150 mm (X ≈ 0.33·L, well inside the apparatus) and varies L as the paper did; series 2 keeps
// the paper's L = 1165 mm and varies D over 110–250 mm (at D = 90 mm X is only 3 mm from the
// fall-off, closer than the noise of a hand-measured Y allows).
//
// Usage: make_samples DATA_DIR
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/experiment.hpp"
#include "model/scene.hpp"

namespace {

constexpr double kA = 0.015875, kB = 0.0254, kH = 0.300, kMu = 0.05;
constexpr double kUL = 0.001, kUD = 0.0002, kUY = 0.0005;

struct Setting {
  double L, D;
};

std::string Mm(double metres, int decimals) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, metres * 1e3);
  return buffer;
}

void Write(const std::string& dir, const std::string& title, const std::string& series,
           const std::string& varied, const std::vector<Setting>& settings, std::uint64_t seed) {
  std::filesystem::create_directories(dir);
  boost::random::mt19937_64 engine(seed);
  boost::random::normal_distribution<double> normal;
  const uphill::Body body = uphill::Body::Spheroid(kA, kB);
  std::ostringstream csv;
  csv << "trial,series,L_mm,D_mm,Y_mm,note\n";
  int trial = 0;
  for (const Setting& s : settings) {
    const uphill::Scene scene(body, uphill::Rails::FromApparatus(s.L, kH, s.D, uphill::LConvention::kHorizontal));
    const double y_true = scene.Rest(kMu)->high;
    // Three trials per setting: the technician re-measures Y each time; L and D are read once.
    const double L = s.L + kUL * normal(engine), D = s.D + kUD * normal(engine);
    for (int repeat = 0; repeat < 3; ++repeat) {
      ++trial;
      csv << series << "-" << trial << "," << series << "," << Mm(L, 1) << "," << Mm(D, 1) << ","
          << Mm(y_true + kUY * normal(engine), 1) << ","
          << (repeat == 0 ? varied + " setting " + std::to_string(trial / 3 + 1) : "") << "\n";
    }
  }
  nlohmann::ordered_json meta;
  meta["format"] = uphill::kExperimentFormat;
  meta["title"] = title;
  meta["operator"] = "synthetic (tools/make_samples)";
  meta["date"] = "2026-11-21";
  meta["notes"] = {
      "SYNTHETIC DATA generated from the uphill model by tools/make_samples (seed " +
          std::to_string(seed) + "), not measured.",
      "True rolling resistance mu = 0.05 (slope threshold): each Y is x_rest(mu) of the true "
      "setting plus Gaussian noise of u(Y) = 0.5 mm; the recorded L and D carry noise of "
      "u(L) = 1 mm and u(D) = 0.2 mm.",
      "The paper's D = 45 mm cannot work (X beyond the crossbar, within 0.12 % of the fall-off, "
      "for every L); series 1 fixes D = 150 mm instead."};
  meta["body"] = {{"type", "spheroid"}, {"a", "15.875 mm"}, {"b", "25.4 mm"}};
  meta["apparatus"] = {{"H", "300 mm"}, {"L_convention", "horizontal"}};
  meta["uncertainties"] = {{"L", "1 mm"}, {"H", "0.5 mm"}, {"D", "0.2 mm"}, {"Y", "0.5 mm"}};
  uphill::WriteFileAtomically(dir + "/experiment.json", meta.dump(2) + "\n");
  uphill::WriteFileAtomically(dir + "/measurements.csv", csv.str());
  // Read back: the generator's output must load without a single row error.
  const auto loaded = uphill::LoadExperiment(dir);
  if (!loaded.Errors().empty()) throw std::runtime_error(loaded.Errors().front());
  std::cout << "wrote " << dir << " (" << loaded.rows.size() << " trials)\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_samples DATA_DIR\n";
    return 2;
  }
  const std::string data = argv[1];
  std::vector<Setting> series1, series2;
  for (double L : {0.800, 0.900, 1.000, 1.100, 1.165, 1.250, 1.350}) series1.push_back({L, 0.150});
  for (double D : {0.110, 0.130, 0.150, 0.170, 0.190, 0.210, 0.230, 0.250}) series2.push_back({1.165, D});
  try {
    Write(data + "/series1-fixed-D", "Series 1: D = 150 mm fixed, L varied (H = 300 mm)", "s1", "L",
          series1, 1);
    Write(data + "/series2-fixed-L", "Series 2: L = 1165 mm fixed, D varied (H = 300 mm)", "s2", "D",
          series2, 2);
  } catch (const std::exception& e) {
    std::cerr << "make_samples: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
