#include "model/rails.hpp"

#include <numbers>

#include "model/number_text.hpp"

namespace uphill {
namespace {


void RequireFinite(const char* quantity, double v) {
  if (!std::isfinite(v)) throw InputError(quantity, "must be a finite number (got " + ExactText(v) + ")");
}

}  // namespace

Rails Rails::FromAngles(double theta, double alpha) {
  RequireFinite("theta", theta);
  RequireFinite("alpha", alpha);
  if (theta < 0.0 || theta >= std::numbers::pi / 2)
    throw InputError("theta", "must lie in [0, 90) deg (got " + ExactText(theta) + " rad)");
  if (alpha <= 0.0 || alpha >= std::numbers::pi)
    throw InputError("alpha", "must lie in (0, 180) deg (got " + ExactText(alpha) + " rad)");
  return Rails{theta, alpha, std::tan(theta), std::tan(alpha / 2)};
}

Rails Rails::FromApparatus(double L, double H, double D, LConvention convention) {
  RequirePositiveFinite("L", L);
  RequirePositiveFinite("D", D);
  RequireFinite("H", H);
  if (H < 0.0) throw InputError("H", "must be >= 0 (got " + ExactText(H) + ")");
  if (convention == LConvention::kAlongRail && !(L > std::hypot(H, D / 2)))
    throw InputError("L", "measured along a rail must exceed sqrt(H^2 + D^2/4) = " +
                              ExactText(std::hypot(H, D / 2)) + " m (got " + ExactText(L) + " m)");
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
