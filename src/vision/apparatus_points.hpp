// The apparatus points a technician can click to calibrate the scene (calibration/README.md, "The
// apparatus frame and the points to use"): O, the two rails at the crossbar, the crossbar's feet
// on the table, and marks on both rails. Their positions follow from the rails (L, H, D) alone,
// so the page offers them and the technician types nothing but what is special to the lab (the
// table's height, the marks' distances).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "model/rails.hpp"
#include "vision/camera.hpp"

namespace uphill {

struct ApparatusPoint {
  std::string name;          // "O", "left rail crossbar", "right rail crossbar", "left foot",
                             // "right foot", "mark 300 left", "mark 300 right"
  Eigen::Vector3d position;  // apparatus frame, m
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // raw pixel, when projected (below)
};

// A rail at horizontal distance t from O is at (t, ±t·tan(α/2), t·tan θ) (docs/physics.md, "Frame
// and apparatus"); the left rail is at +y. `crossbar_x`: horizontal distance O → crossbar (m);
// `table_z`: height of the table under the crossbar's feet (m, 0: O's height); `marks_x`:
// horizontal distances of marks on both rails (m; those outside (0, crossbar_x) are left out).
// Exact (closed forms).
std::vector<ApparatusPoint> ApparatusCalibrationPoints(const Rails& rails, double crossbar_x, double table_z,
                                                       const std::vector<double>& marks_x);

// The points really in view of the camera, with their raw pixels: in front of it, inside the
// image by 2 px, and not folded back into the image by the distortion polynomial (a ray far
// outside the field of view whose undistorted pixel names another ray). Projection accuracy: as
// camera.hpp.
std::vector<ApparatusPoint> VisibleApparatusPoints(const CameraIntrinsics& camera, const CameraPose& pose,
                                                   const std::vector<ApparatusPoint>& points);

}  // namespace uphill
