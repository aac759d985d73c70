#include "vision/apparatus_points.hpp"

#include <cmath>

namespace uphill {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<ApparatusPoint> ApparatusCalibrationPoints(const Rails& rails, double crossbar_x, double table_z,
                                                       const std::vector<double>& marks_x) {
  const double T = rails.tan_half_alpha, B = rails.tan_theta, L = crossbar_x;
  std::vector<ApparatusPoint> points = {{"O", Vector3d::Zero()},
                                        {"left rail crossbar", Vector3d(L, L * T, L * B)},
                                        {"right rail crossbar", Vector3d(L, -L * T, L * B)},
                                        {"left foot", Vector3d(L, L * T, table_z)},
                                        {"right foot", Vector3d(L, -L * T, table_z)}};
  for (double m : marks_x) {
    if (!(m > 0 && m < L)) continue;
    const int mm = static_cast<int>(std::lround(m * 1000));
    points.push_back({"mark " + std::to_string(mm) + " left", Vector3d(m, m * T, m * B)});
    points.push_back({"mark " + std::to_string(mm) + " right", Vector3d(m, -m * T, m * B)});
  }
  return points;
}

std::vector<ApparatusPoint> VisibleApparatusPoints(const CameraIntrinsics& camera, const CameraPose& pose,
                                                   const std::vector<ApparatusPoint>& points) {
  std::vector<ApparatusPoint> out;
  for (const ApparatusPoint& p : points) {
    const Vector3d q = pose.rotation * p.position + pose.translation;
    if (q.z() <= 0) continue;
    const Vector2d pixel = ProjectApparatusPoint(camera, pose, p.position);
    if (pixel.x() < 2 || pixel.y() < 2 || pixel.x() > camera.width - 3 || pixel.y() > camera.height - 3) continue;
    if ((UndistortPixel(camera, pixel) - Vector2d(q.x() / q.z(), q.y() / q.z())).norm() > 1e-6) continue;
    out.push_back({p.name, p.position, pixel});
  }
  return out;
}

}  // namespace uphill
