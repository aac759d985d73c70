#include "model/rails.hpp"

#include <numbers>
#include <sstream>

namespace uphill {
namespace {

std::string Num(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

void RequireFinite(const char* quantity, double v) {
  if (!std::isfinite(v)) throw InputError(quantity, "must be a finite number (got " + Num(v) + ")");
}

}  // namespace

Rails Rails::FromAngles(double theta, double alpha) {
  RequireFinite("theta", theta);
  RequireFinite("alpha", alpha);
  if (theta < 0.0 || theta >= std::numbers::pi / 2)
    throw InputError("theta", "must lie in [0, 90) deg (got " + Num(theta) + " rad)");
  if (alpha <= 0.0 || alpha >= std::numbers::pi)
    throw InputError("alpha", "must lie in (0, 180) deg (got " + Num(alpha) + " rad)");
  return Rails{theta, alpha, std::tan(theta), std::tan(alpha / 2)};
}

Rails Rails::FromApparatus(double L, double H, double D, LConvention convention) {
  RequirePositiveFinite("L", L);
  RequirePositiveFinite("D", D);
  RequireFinite("H", H);
  if (H < 0.0) throw InputError("H", "must be >= 0 (got " + Num(H) + ")");
  if (convention == LConvention::kAlongRail && !(L > std::hypot(H, D / 2)))
    throw InputError("L", "measured along a rail must exceed sqrt(H^2 + D^2/4) = " +
                              Num(std::hypot(H, D / 2)) + " m (got " + Num(L) + " m)");
  const double horizontal = HorizontalDistance(L, H, D, convention);
  Rails rails;
  rails.tan_theta = H / horizontal;
  rails.tan_half_alpha = D / (2 * horizontal);
  rails.theta = std::atan2(H, horizontal);
  rails.alpha = 2 * std::atan2(D / 2, horizontal);
  return rails;
}

double Rails::HalfAngleBetweenRails() const {
  // tanφ = tan(α/2)·cosθ, with cosθ = 1/sqrt(1 + tan²θ) to reuse the exact slopes.
  return std::atan2(tan_half_alpha, std::hypot(1.0, tan_theta));
}

}  // namespace uphill
