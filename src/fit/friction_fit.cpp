#include "fit/friction_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "internal/line_problem.hpp"
#include "fit/least_squares_line.hpp"
#include "fit/york_line.hpp"
#include "model/input_error.hpp"
#include "model/spheroid_on_line_rails.hpp"
#include "model/spheroid_on_rods.hpp"
#include "model/number_text.hpp"

namespace uphill {
namespace {

using namespace internal;

// The closed-form geometry of one row: a spheroid (a, b) on line rails - also a sphere on line
// rails (a = b = R) and a sphere on rods (a = b = R + r on the rod axes), exactly as Scene builds
// its path.
struct ClosedFormRow {
  double a, b, tan_theta, tan_half_alpha;

  template <typename T>
  T RestX(const T& mu) const {
    return SpheroidOnLineRails<T>(T(a), T(b), T(tan_theta), T(tan_half_alpha)).RestX(mu);
  }
};

// Rows with a closed form: residuals (Y_i − s·x_rest,i(μ))/σ_i, differentiated by Ceres' Jets
// through the model's own SpheroidOnLineRails<T>. P = 1: θ = (μ); P = 2: θ = (μ, s).
template <int P>
struct ClosedFormResiduals {
  const std::vector<ClosedFormRow>* rows;
  const std::vector<double>* y;
  const std::vector<double>* inv_sigma;

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    for (std::size_t i = 0; i < rows->size(); ++i) {
      T x = (*rows)[i].RestX(theta[0]);
      if constexpr (P == 2) x = x * theta[1];
      residuals[i] = ((*y)[i] - x) * (*inv_sigma)[i];
    }
    return true;
  }
};

// Spheroids on rods: the model's numeric contact geometry, differentiated by central
// differences (RestX accepts μ < 0, the nearest rest position, so the bound μ = 0 is no edge).
template <int P>
struct RodResiduals {
  const std::vector<SpheroidOnRods>* rods;
  const std::vector<double>* y;
  const std::vector<double>* inv_sigma;

  bool operator()(const double* theta, double* residuals) const {
    for (std::size_t i = 0; i < rods->size(); ++i) {
      double x = (*rods)[i].RestX(theta[0]);
      if constexpr (P == 2) x *= theta[1];
      residuals[i] = ((*y)[i] - x) * (*inv_sigma)[i];
    }
    return true;
  }
};

struct Rows {
  std::vector<ClosedFormRow> closed;
  std::vector<std::size_t> closed_index;
  std::vector<double> closed_y, closed_inv_sigma;
  std::vector<SpheroidOnRods> rods;
  std::vector<std::size_t> rod_index;
  std::vector<double> rod_y, rod_inv_sigma;
};

void Validate(const FrictionData& data, std::size_t parameters) {
  const std::size_t n = data.size();
  if (n < parameters)
    throw InputError("rows", "the friction fit with " + std::to_string(parameters) +
                                 " parameter(s) needs at least " + std::to_string(parameters) +
                                 " rows (got " + std::to_string(n) + ")");
  if (data.y.size() != n)
    throw InputError("Y", "must have one value per scene (" + std::to_string(n) + " scenes, got " +
                              std::to_string(data.y.size()) + ")");
  if (!data.u_y.empty() && data.u_y.size() != n)
    throw InputError("u(Y)", "must have one value per scene (" + std::to_string(n) +
                                 " scenes, got " + std::to_string(data.u_y.size()) + ")");
  if (!data.u_model.empty()) {
    if (data.u_model.size() != n)
      throw InputError("u_model", "must have one value per scene (" + std::to_string(n) +
                                      " scenes, got " + std::to_string(data.u_model.size()) + ")");
    if (data.u_y.empty())
      throw InputError("u_model", "needs u(Y) (the effective variance is u(Y)^2 + u_model^2)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!data.u_model.empty() && !(std::isfinite(data.u_model[i]) && data.u_model[i] >= 0.0))
      throw InputError("u_model[" + std::to_string(i) + "]",
                       "must be finite and >= 0 (got " + ExactText(data.u_model[i]) + ")");
    if (!std::isfinite(data.y[i]))
      throw InputError("Y[" + std::to_string(i) + "]",
                       "must be finite (got " + ExactText(data.y[i]) + ")");
    if (!data.u_y.empty() && !(std::isfinite(data.u_y[i]) && data.u_y[i] > 0.0))
      throw InputError(
          "u(Y)[" + std::to_string(i) + "]",
          "must be finite and > 0 for the friction fit (got " + ExactText(data.u_y[i]) + ")");
  }
}

// σ_i of row i: u(Y_i), combined with u_model,i when given (effective variance; see the
// header); 1 without stated uncertainties. hypot: no overflow or underflow in the squares.
double Sigma(const FrictionData& data, std::size_t i) {
  if (data.u_y.empty()) return 1.0;
  return data.u_model.empty() ? data.u_y[i] : std::hypot(data.u_y[i], data.u_model[i]);
}

Rows Classify(const FrictionData& data) {
  Rows rows;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const Scene& scene = data.scenes[i];
    const Body& body = scene.body();
    const double r = scene.rod_radius();
    const double B = scene.rails().tan_theta, T = scene.rails().tan_half_alpha;
    const double inv_sigma = 1.0 / Sigma(data, i);
    switch (body.kind) {
      case BodyKind::kDoubleCone:
        throw InputError("scene[" + std::to_string(i) + "]",
                         "a double cone has a constant slope and no rest position to fit; the "
                         "friction model needs a sphere or a spheroid");
      case BodyKind::kSphere:
      case BodyKind::kSpheroid:
        if (body.kind == BodyKind::kSpheroid && r > 0.0) {
          rows.rods.emplace_back(body.across, body.along, B, T, r);
          rows.rod_index.push_back(i);
          rows.rod_y.push_back(data.y[i]);
          rows.rod_inv_sigma.push_back(inv_sigma);
        } else {
          const double a = body.across + r;
          const double b = body.kind == BodyKind::kSphere ? a : body.along;
          rows.closed.push_back({a, b, B, T});
          rows.closed_index.push_back(i);
          rows.closed_y.push_back(data.y[i]);
          rows.closed_inv_sigma.push_back(inv_sigma);
        }
        break;
    }
  }
  return rows;
}

// x_rest,i(μ) of row i from the fit's own geometry (what the cost functions evaluate).
std::vector<double> FitRestX(const Rows& rows, std::size_t n, double mu) {
  std::vector<double> x(n);
  for (std::size_t j = 0; j < rows.closed.size(); ++j)
    x[rows.closed_index[j]] = rows.closed[j].RestX(mu);
  for (std::size_t j = 0; j < rows.rods.size(); ++j) x[rows.rod_index[j]] = rows.rods[j].RestX(mu);
  return x;
}

// The median of the per-row inversions of x_rest(μ) = Y (closed-form rows: K = q·A·sqrt(P)/
// sqrt(1 − q²), q = Y/x_max, μ = (K − B)/(1 + A²)), clamped at 0; 0 if no row inverts.
double MuFromInversion(const Rows& rows) {
  std::vector<double> mu;
  for (std::size_t j = 0; j < rows.closed.size(); ++j) {
    const ClosedFormRow& g = rows.closed[j];
    const SpheroidOnLineRails<double> path(g.a, g.b, g.tan_theta, g.tan_half_alpha);
    const double q = rows.closed_y[j] / path.x_max();
    if (!(q > 0.0 && q < 1.0)) continue;
    const double k = q * path.A() * std::sqrt(path.P()) / std::sqrt((1.0 - q) * (1.0 + q));
    mu.push_back((k - g.tan_theta) / (1.0 + path.A() * path.A()));
  }
  if (mu.empty()) return 0.0;
  std::nth_element(mu.begin(), mu.begin() + static_cast<std::ptrdiff_t>(mu.size() / 2), mu.end());
  return std::max(0.0, mu[mu.size() / 2]);
}

template <int P>
FitReport FitFrictionImpl(const FrictionData& data, const FrictionOptions& options) {
  Validate(data, P);
  const std::size_t n = data.size();
  const bool stated = !data.u_y.empty();
  const Rows rows = Classify(data);
  const FitOptions& fit = options.fit;

  double mu0 = 0.0;
  if (options.mu_start) {
    mu0 = *options.mu_start;
    if (!(std::isfinite(mu0) && mu0 >= 0.0))
      throw InputError("mu start", "must be finite and >= 0 (got " + ExactText(mu0) + ")");
  } else if (fit.seed_with_closed_form) {
    mu0 = MuFromInversion(rows);
  }
  // The fit evaluates the model through its own copy of each row's geometry; make sure it is
  // the Scene's, to the last few ulp, before trusting any number it produces.
  const std::vector<double> x0 = FitRestX(rows, n, mu0);
  for (std::size_t i = 0; i < n; ++i) {
    const double reference = data.scenes[i].Rest(mu0)->high;
    if (!(std::abs(x0[i] - reference) <= 1e-13 * std::abs(reference)))
      throw std::logic_error("friction fit: row " + std::to_string(i) + " x_rest = " + ExactText(x0[i]) +
                             " differs from Scene::Rest " + ExactText(reference));
  }
  std::array<double, P> theta{};
  theta[0] = mu0;
  if constexpr (P == 2) {
    // The least-squares scale at μ0 (closed form), or 1.
    long double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const long double sigma = Sigma(data, i);
      const long double w = 1.0L / (sigma * sigma);
      sxy += w * x0[i] * data.y[i];
      sxx += w * x0[i] * x0[i];
    }
    theta[1] = fit.seed_with_closed_form && sxx > 0 ? static_cast<double>(sxy / sxx) : 1.0;
  }

  ceres::Problem problem;  // owns the cost functions
  std::vector<const ceres::CostFunction*> costs;
  if (!rows.closed.empty()) {
    auto* cost = new ceres::AutoDiffCostFunction<ClosedFormResiduals<P>, ceres::DYNAMIC, P>(
        new ClosedFormResiduals<P>{&rows.closed, &rows.closed_y, &rows.closed_inv_sigma},
        static_cast<int>(rows.closed.size()));
    costs.push_back(cost);
    problem.AddResidualBlock(cost, nullptr, theta.data());
  }
  if (!rows.rods.empty()) {
    auto* cost =
        new ceres::NumericDiffCostFunction<RodResiduals<P>, ceres::CENTRAL, ceres::DYNAMIC, P>(
            new RodResiduals<P>{&rows.rods, &rows.rod_y, &rows.rod_inv_sigma},
            ceres::TAKE_OWNERSHIP, static_cast<int>(rows.rods.size()));
    costs.push_back(cost);
    problem.AddResidualBlock(cost, nullptr, theta.data());
  }
  problem.SetParameterLowerBound(theta.data(), 0, 0.0);

  FitReport report;
  report.method = FitMethod::kFriction;
  report.n = n;
  report.uses_stated_uncertainties = stated;
  report.primary_scaling = stated ? ErrorScaling::kUnscaled : ErrorScaling::kScaled;
  report.outlier_threshold = fit.outlier_threshold;
  report.solver =
      RunCeres(fit, fit.seed_with_closed_form || options.mu_start.has_value(), &problem);
  report.solver.refinement_steps = RefineGaussNewton(costs, theta.data(), P, 0.0);

  const auto covariance = CeresCovariance(&problem, theta.data(), P);
  if (!covariance)
    throw InputError("scenes", P == 2 ? "the rows do not determine both mu and s (singular "
                                        "covariance): use at least two different apparatus "
                                        "settings, or do not fit the scale"
                                      : "the rows do not determine mu (singular covariance)");
  report.covariance = *covariance;

  // Rows from the Scene itself: the reported fit is the model's, not the fit's copy of it.
  const double mu = std::max(0.0, theta[0]);
  const double scale = P == 2 ? theta[P - 1] : 1.0;
  long double chi2 = 0, sum_log_sigma2 = 0;
  report.rows.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    RowResult& row = report.rows[i];
    row.row = i;
    row.fitted = scale * data.scenes[i].Rest(mu)->high;
    row.residual = data.y[i] - row.fitted;
    if (stated) {
      row.sigma = Sigma(data, i);
      row.normalised = row.residual / row.sigma;
      chi2 += static_cast<long double>(row.normalised) * row.normalised;
      sum_log_sigma2 += 2.0L * std::log(static_cast<long double>(row.sigma));
    } else {
      chi2 += static_cast<long double>(row.residual) * row.residual;
    }
  }
  report.chi2 = static_cast<double>(chi2);
  if (!stated) {
    const double sd = n > P ? std::sqrt(report.chi2 / static_cast<double>(n - P)) : 0.0;
    for (RowResult& row : report.rows) {
      row.sigma = sd;
      row.normalised = sd > 0.0 ? row.residual / sd : 0.0;
    }
  }
  Eigen::VectorXd values(P);
  values(0) = mu;
  if constexpr (P == 2) values(1) = scale;
  FinishReport(report,
               P == 2 ? std::vector<std::string>{"mu", "s"} : std::vector<std::string>{"mu"},
               values, stated);
  SetInformationCriteria(report, static_cast<double>(sum_log_sigma2));
  if (mu == 0.0)
    report.notes.push_back(
        "mu is at its bound 0: the covariance is that of the unconstrained "
        "problem; read the result as mu <= its standard error");
  if (!data.u_model.empty())
    report.notes.push_back(
        "sigma_i^2 = u(Y)^2 + u_model^2: the model value's uncertainty (from the inputs') is "
        "included");
  if (!rows.rods.empty())
    report.notes.push_back(std::to_string(rows.rods.size()) +
                           " spheroid-on-rods rows use central numeric derivatives");
  if (!report.solver.converged) report.notes.push_back("Ceres: " + report.solver.termination);
  return report;
}

}  // namespace

FitReport FitFriction(const FrictionData& data, const FrictionOptions& options) {
  return options.fit_scale ? FitFrictionImpl<2>(data, options) : FitFrictionImpl<1>(data, options);
}

FrictionVersusLine CompareFrictionWithLine(const FrictionData& data,
                                           const FrictionOptions& options) {
  FrictionVersusLine result{FitFriction(data, options), FitReport{}, ModelComparison{}};
  LineData line;
  line.x.reserve(data.size());
  for (const Scene& scene : data.scenes) line.x.push_back(*scene.x_eq());
  line.y = data.y;
  line.u_y = data.u_y;
  // The line sees the uncertainties the friction fit sees: with u_model, York's line with
  // u(X) = u_model (σ_i² = u(Y)² + k²u_model², the friction fit's at k = 1); WLS against
  // u(Y) alone would charge the line with the model's scatter and favour friction unfairly.
  if (!data.u_model.empty()) {
    line.u_x = data.u_model;
    result.line = FitErrorsInVariables(line, options.fit);
  } else {
    result.line = data.u_y.empty() ? FitOrdinaryLeastSquares(line, options.fit)
                                   : FitWeightedLeastSquares(line, options.fit);
  }
  result.comparison = CompareModels(result.line, result.friction);
  return result;
}

}  // namespace uphill
