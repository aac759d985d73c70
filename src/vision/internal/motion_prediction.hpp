// The body's motion through its last centres, and where it is at a given time. Private to
// src/vision/.
//
// A least-squares polynomial in time through the samples: a parabola from four samples on
// (constant acceleration), a line through two or three, the centre itself from one. It is exact
// for a motion of that degree, to rounding (tests/vision_motion_prediction_test.cpp).
//
// Under a rolling shutter each row is read at its own time, t = frame_t + row·δ (δ the rows'
// delay), and the row is the one where the centre lies at that time: a fixed point, which
// AtOwnRow solves by iteration. Its map contracts by |d row/dt|·δ, the centre's speed across the
// rows times the delay (0.01 for a phone: 425 rows/s × 23 µs): each step cuts the error of
// the time a hundredfold, from the 11 ms of the frame time's. Taking the prediction at the
// frame's time and shifting it by v·row·δ instead (the row read off that unshifted prediction)
// misses by ½·a·(row·δ)² plus v·δ·(the rows the centre moved in row·δ): a fraction of a pixel
// along the motion where the ball moves tens of pixels per frame, enough for the tracker's
// check of its prediction to fail.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

namespace uphill::internal {

struct TimedCentre {
  double t;           // s
  Eigen::Vector2d c;  // any units (the tracker's: (x, z), m)
};

struct MotionState {
  double t;  // s
  Eigen::Vector2d centre, velocity, acceleration;  // per s, per s²; acceleration 0 below degree 2
};

class MotionFit {
 public:
  // The fit through `samples` (any order, distinct times); nullopt when there are none or the
  // fit is not finite.
  static std::optional<MotionFit> Through(const std::vector<TimedCentre>& samples);

  MotionState At(double t) const;
  // The state at the time its row is read: t = frame_t + row(centre(t))·row_delay, with `row`
  // the image row (px) of a centre. row_delay = 0 gives At(frame_t).
  MotionState AtOwnRow(double frame_t, double row_delay,
                       const std::function<double(const Eigen::Vector2d&)>& row) const;
  int degree() const { return degree_; }

 private:
  Eigen::Matrix<double, 3, 2> coef_ = Eigen::Matrix<double, 3, 2>::Zero();  // in (t - t0)^k
  int degree_ = 0;
  double t0_ = 0;
};

}  // namespace uphill::internal
