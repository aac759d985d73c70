// The full model's geometry for the tests of its parts (body_shading, outline_fit): a 640×480
// camera with fx = 900 px and k1 = -0.1, 0.6 m from the apparatus plane, looking at (0.40, 0, 0.10)
// from slightly above; a sphere of radius `radius`.
#pragma once

#include <Eigen/Core>

#include "internal/outline_fit.hpp"
#include "vision/camera.hpp"

namespace uphill::internal {

inline OutlineGeometry TestOutlineGeometry(double radius) {
  OutlineGeometry g;
  g.cal.camera.width = 640;
  g.cal.camera.height = 480;
  g.cal.camera.fx = g.cal.camera.fy = 900;
  g.cal.camera.cx = 320, g.cal.camera.cy = 240;
  g.cal.camera.distortion = {-0.1, 0.0, 0.0, 0.0};
  g.cal.pose = LookAtPose(Eigen::Vector3d(0.40, -0.6, 0.15), Eigen::Vector3d(0.40, 0, 0.10));
  g.a = radius;
  g.s = 1;
  g.eye = g.eye_s = CameraCentre(g.cal.pose);
  g.to_apparatus = g.cal.pose.rotation.transpose();
  return g;
}

}  // namespace uphill::internal
