#include "model/scene.hpp"

#include <cmath>

#include "model/number_text.hpp"

namespace uphill {
namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;


PathPoint FromSpheroid(double x, const SpheroidPathPoint<double>& p) {
  return PathPoint{x, p.z, p.dzdx, p.r_star, p.x_contact};
}

}  // namespace

Scene::Path Scene::MakePath(const Body& body, const Rails& rails, double rod_radius) {
  const double B = rails.tan_theta, T = rails.tan_half_alpha;
  if (!(rod_radius >= 0.0) || !std::isfinite(rod_radius))
    throw InputError("rod radius", "must be a finite number >= 0 (got " + ExactText(rod_radius) + ")");
  switch (body.kind) {
    case BodyKind::kSphere:
      if (rod_radius == 0.0) return SpheroidOnLineRails<double>(body.across, body.across, B, T);
      return SphereOnRods{SpheroidOnLineRails<double>(body.across + rod_radius,
                                                      body.across + rod_radius, B, T),
                          body.across / (body.across + rod_radius)};
    case BodyKind::kSpheroid:
      if (rod_radius == 0.0) return SpheroidOnLineRails<double>(body.across, body.along, B, T);
      return SpheroidOnRods(body.across, body.along, B, T, rod_radius);
    case BodyKind::kDoubleCone: {
      if (rod_radius != 0.0)
        throw InputError("rod diameter",
                         "a double cone on round rods is not modelled (use line rails, 0 mm)");
      DoubleConeOnLineRails<double> cone(body.across, body.along, B, T);
      if (!cone.valid())
        throw InputError("body",
                         "the double cone cannot rest on both rails: 1 + tan^2(theta) - "
                         "(R/h)^2 tan^2(alpha/2) = " + ExactText(cone.Q()) + " <= 0");
      return cone;
    }
  }
  throw InputError("body", "unknown body kind");
}

Scene::Scene(const Body& body, const Rails& rails, double rod_radius)
    : body_(body), rails_(rails), rod_radius_(rod_radius), path_(MakePath(body, rails, rod_radius)) {}

std::optional<double> Scene::x_eq() const {
  return std::visit(
      Overloaded{[](const SpheroidOnLineRails<double>& p) -> std::optional<double> { return p.x_eq(); },
                 [](const SphereOnRods& p) -> std::optional<double> { return p.enlarged.x_eq(); },
                 [](const SpheroidOnRods& p) -> std::optional<double> { return p.x_eq(); },
                 [](const DoubleConeOnLineRails<double>&) -> std::optional<double> { return {}; }},
      path_);
}

std::optional<double> Scene::z_eq() const {
  return std::visit(
      Overloaded{[](const SpheroidOnLineRails<double>& p) -> std::optional<double> { return p.z_eq(); },
                 [](const SphereOnRods& p) -> std::optional<double> { return p.enlarged.z_eq(); },
                 [](const SpheroidOnRods& p) -> std::optional<double> { return p.z_eq(); },
                 [](const DoubleConeOnLineRails<double>&) -> std::optional<double> { return {}; }},
      path_);
}

double Scene::x_max() const {
  return std::visit(Overloaded{[](const SpheroidOnLineRails<double>& p) { return p.x_max(); },
                               [](const SphereOnRods& p) { return p.enlarged.x_max(); },
                               [](const SpheroidOnRods& p) { return p.x_max(); },
                               [](const DoubleConeOnLineRails<double>& p) { return p.x_fall(); }},
                    path_);
}

double Scene::x_low() const {
  return std::visit(Overloaded{[](const SpheroidOnLineRails<double>& p) { return p.x_low(); },
                               [](const SphereOnRods& p) { return p.enlarged.x_low(); },
                               [](const SpheroidOnRods& p) { return p.x_low(); },
                               [](const DoubleConeOnLineRails<double>& p) { return p.x_low(); }},
                    path_);
}

std::optional<double> Scene::FallOffMargin() const {
  return std::visit(
      Overloaded{
          [](const SpheroidOnLineRails<double>& p) -> std::optional<double> { return p.FallOffMargin(); },
          [](const SphereOnRods& p) -> std::optional<double> { return p.enlarged.FallOffMargin(); },
          [](const SpheroidOnRods& p) -> std::optional<double> { return p.x_max() - p.x_eq(); },
          [](const DoubleConeOnLineRails<double>&) -> std::optional<double> { return {}; }},
      path_);
}

bool Scene::rolls_up() const {
  if (const auto* c = cone()) return c->rolls_up();
  return true;
}

PathPoint Scene::At(double x) const {
  if (!std::isfinite(x) || x < x_low() || x > x_max())
    throw InputError("x", "must lie on the path, in [" + ExactText(x_low()) + ", " + ExactText(x_max()) +
                              "] m (got " + ExactText(x) + " m)");
  return std::visit(
      Overloaded{[x](const SpheroidOnLineRails<double>& p) { return FromSpheroid(x, p.At(x)); },
                 [x](const SphereOnRods& p) {
                   PathPoint q = FromSpheroid(x, p.enlarged.At(x));
                   q.r_star *= p.shrink;  // true contact: C + R/(R+r)·(F − C)
                   q.x_contact = x + p.shrink * (q.x_contact - x);
                   return q;
                 },
                 [x](const SpheroidOnRods& p) { return FromSpheroid(x, p.At(x)); },
                 [x](const DoubleConeOnLineRails<double>& p) {
                   return PathPoint{x, p.Z(x), -p.B(), p.RStar(x), p.ContactX(x)};
                 }},
      path_);
}

std::optional<RestBand> Scene::Rest(double mu) const {
  if (!(mu >= 0.0) || !std::isfinite(mu))
    throw InputError("mu", "must be a finite number >= 0 (got " + ExactText(mu) + ")");
  return std::visit(
      Overloaded{[mu](const SpheroidOnLineRails<double>& p) -> std::optional<RestBand> {
                   return RestBand{p.RestX(-mu), p.RestX(mu)};
                 },
                 [mu](const SphereOnRods& p) -> std::optional<RestBand> {
                   return RestBand{p.enlarged.RestX(-mu), p.enlarged.RestX(mu)};
                 },
                 [mu](const SpheroidOnRods& p) -> std::optional<RestBand> {
                   return RestBand{p.RestX(-mu), p.RestX(mu)};
                 },
                 [](const DoubleConeOnLineRails<double>&) -> std::optional<RestBand> { return {}; }},
      path_);
}

bool Scene::RestsEverywhere(double mu) const {
  if (const auto* c = cone()) return std::abs(c->B()) <= mu;
  return false;
}

const DoubleConeOnLineRails<double>* Scene::cone() const {
  return std::get_if<DoubleConeOnLineRails<double>>(&path_);
}

std::optional<double> Scene::theta0() const {
  if (const auto* c = cone()) return c->theta0();
  return {};
}

std::optional<double> Scene::theta0_fixed_phi() const {
  if (body_.kind != BodyKind::kDoubleCone) return {};
  const double product = std::tan(rails_.HalfAngleBetweenRails()) * body_.across / body_.along;
  if (product >= 1.0) return {};
  return std::asin(product);
}

double Scene::KineticFactor(double x) const {
  const double r_star = At(x).r_star;
  return 1.0 + body_.InertiaFactor() * body_.across * body_.across / (r_star * r_star);
}

}  // namespace uphill
