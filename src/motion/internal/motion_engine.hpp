// Internal to src/motion: the interface both methods implement (see motion.hpp).
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "motion/motion.hpp"
#include "path_coordinate.hpp"

namespace uphill {

class Motion::Engine {
 public:
  Engine(const Scene& scene, double x0) : scene_(scene), x0_(x0) {}
  virtual ~Engine() = default;
  virtual double TimeAt(double x) const = 0;
  virtual MotionSample At(double t) const = 0;
  virtual MotionSample AtPosition(double x) const { return At(TimeAt(x)); }

  const Scene& scene() const { return scene_; }
  double x0() const { return x0_; }
  int direction() const { return direction_; }
  const std::vector<MotionEvent>& events() const { return events_; }
  double end_time() const {
    if (events_.empty()) return std::numeric_limits<double>::infinity();
    const MotionEventKind k = events_.back().kind;
    return k == MotionEventKind::kFallOff || k == MotionEventKind::kReachesO
               ? events_.back().t
               : std::numeric_limits<double>::infinity();
  }

 protected:
  Scene scene_;
  double x0_;
  int direction_ = 0;
  std::vector<MotionEvent> events_;
};

namespace internal {

inline double Inf() { return std::numeric_limits<double>::infinity(); }

// Sphere/spheroid path in the ellipse form (nullptr-like empty optional for cone and rods).
bool IsEllipse(const Scene& scene);
EllipseCoordinate MakeEllipse(const Scene& scene);

std::unique_ptr<Motion::Engine> MakeQuadratureEngine(const Scene& scene, double x0,
                                                     const MotionOptions& options);
std::unique_ptr<Motion::Engine> MakeOdeEngine(const Scene& scene, double x0,
                                              const MotionOptions& options);

}  // namespace internal
}  // namespace uphill
