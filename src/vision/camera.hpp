// Camera: the pinhole camera with lens distortion that films the apparatus, and its pose in the
// apparatus frame of docs/physics.md "Frame and apparatus" (O the rails' meeting point, x along the centre line toward the
// rising end, y across, z up). Everything the vision layer computes goes through these few
// functions, so that the renderer of synthetic clips, the calibration and the tracker agree on
// one camera model: OpenCV's (cv::projectPoints, cv::undistortPoints).
//
// Conventions
//  - Pixels: OpenCV's. (0, 0) is the centre of the top-left pixel, u to the right, v down.
//    "Raw" pixel coordinates are those of the recorded (distorted) frame.
//  - Intrinsics K = [fx 0 cx; 0 fy cy; 0 0 1] in pixels; distortion coefficients in OpenCV's
//    order (k1, k2, p1, p2[, k3[, k4, k5, k6]]), dimensionless; empty means none.
//  - Camera frame: OpenCV's (x right, y down, z along the optical axis), metres.
//  - Pose: a point P of the apparatus frame (metres) is at rotation·P + translation in the
//    camera frame.
//  - Units: metres inside the library; the files (calibration/README.md) state theirs.
//
// Accuracy: projection is OpenCV's closed form (a few ulp). UndistortPixel inverts the lens
// model iteratively; its round trip Project(Undistort(p)) = p holds to < 1e-6 px for the
// distortions of real lenses within the image (tests/vision_camera_test.cpp).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace uphill {

struct CameraIntrinsics {
  int width = 0, height = 0;              // image size, pixels
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  std::vector<double> distortion;         // OpenCV order; empty: no distortion
};

struct CameraPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // apparatus -> camera
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // metres
};

// Raw pixel of a point in the camera frame (metres). Throws InputError ("point") unless the
// point lies in front of the camera (z > 0).
Eigen::Vector2d ProjectCameraPoint(const CameraIntrinsics& camera, const Eigen::Vector3d& point);

// Raw pixel of a point of the apparatus frame (metres).
Eigen::Vector2d ProjectApparatusPoint(const CameraIntrinsics& camera, const CameraPose& pose,
                                      const Eigen::Vector3d& point);

// The undistorted normalised image coordinates (X/Z, Y/Z in the camera frame) of a raw pixel:
// the direction of its viewing ray is (x, y, 1).
Eigen::Vector2d UndistortPixel(const CameraIntrinsics& camera, const Eigen::Vector2d& raw);

// How far from the optical axis the lens model holds: the normalised radius r = |(x, y)|/z up to
// which its radial mapping r·(1 + k1·r² + k2·r⁴ + k3·r⁶)/(1 + k4·r² + k5·r⁴ + k6·r⁶) still grows
// with r (infinity where it always does; searched to r = 5, 79°, in steps of 1e-3). Beyond it the
// polynomial folds back: a point far outside the picture "projects" inside it, so whoever projects
// points that may lie outside the view (a rail's whole length) keeps to r below this.
double LensModelReach(const CameraIntrinsics& camera);

// The camera's centre in the apparatus frame (metres): −rotationᵀ·translation.
Eigen::Vector3d CameraCentre(const CameraPose& pose);

// The pose of a camera at `centre` looking at `target` (apparatus frame, metres), turned about
// its optical axis so that `up` points up in the image (v decreasing). Throws InputError
// ("camera pose") when centre = target or the viewing direction is parallel to `up`.
CameraPose LookAtPose(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                      const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

// Batch forms of the above (one OpenCV call for all points: a renderer maps every pixel of a
// frame at once). Same contracts and accuracy as the single-point functions.
std::vector<Eigen::Vector2d> ProjectApparatusPoints(const CameraIntrinsics& camera,
                                                    const CameraPose& pose,
                                                    const std::vector<Eigen::Vector3d>& points);
std::vector<Eigen::Vector2d> UndistortPixels(const CameraIntrinsics& camera,
                                             const std::vector<Eigen::Vector2d>& raw);

// Throws InputError("<context>.<quantity>", rule) unless the intrinsics are usable: width and
// height > 0, fx, fy > 0 and finite, cx, cy finite, 0, 4, 5 or 8 finite distortion coefficients.
void ValidateIntrinsics(const CameraIntrinsics& camera, const std::string& context);

// Files (formats documented in calibration/README.md; written atomically). Readers throw
// InputError naming the file, the key and the rule broken (missing key, wrong type, a unit that
// does not match, fx ≤ 0, a rotation that is not orthonormal, ...).
//   camera file  "format": "uphill-camera/1": intrinsics + calibration diagnostics
//   scene file   "format": "uphill-scene/1": the camera file's intrinsics + the pose (+ its inputs)
CameraIntrinsics ReadCameraFile(const std::string& path);
struct SceneCalibration {
  CameraIntrinsics camera;
  CameraPose pose;
};
SceneCalibration ReadSceneFile(const std::string& path);

// A point of known position seen in a frame: what a scene's pose is solved from
// (vision/calibration.hpp CalibrateScene), and what a scene file keeps of it.
struct ScenePoint {
  std::string label;                                   // e.g. "file.csv, row 3" or a point's name
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();     // raw pixel (u, v)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // apparatus frame, metres
};

// What a scene's pose was solved from, kept in its file so that a person can check it and the
// page of `uphill serve` can restore the clicks after a reload or in another browser: the points
// (label = the point's name), the marks' distances from O along the rails and the height of the
// table under the crossbar's feet. All optional: files written by other means, and scene files
// written before these were kept, have none, and read as empty.
struct SceneInputs {
  std::vector<ScenePoint> points;
  std::vector<double> marks_x;    // metres, in the order given
  std::optional<double> table_z;  // metres; nullopt: not recorded
};

// How a calibration was obtained, stored in the files for the person who checks them; the
// readers accept and ignore it (the numbers above are all the vision layer uses).
struct CalibrationSummary {
  std::string method;                // e.g. "chessboard 9x6 inner corners, 20 mm squares"
  double rms_px = -1;                // RMS reprojection error, pixels; < 0: not applicable
  std::string verdict;               // "good", "poor", or "exact" for a synthetic camera
  std::vector<std::string> reasons;  // why the verdict (plain sentences)
  std::vector<std::string> inputs;   // one line per view or point: what was used, rejected, why
};
// Throw std::runtime_error naming the path when the file cannot be written; InputError
// (ValidateIntrinsics, or a rotation that is not orthonormal) before writing anything.
void WriteCameraFile(const std::string& path, const CameraIntrinsics& camera,
                     const CalibrationSummary& summary);
void WriteSceneFile(const std::string& path, const SceneCalibration& scene,
                    const CalibrationSummary& summary, const SceneInputs& inputs = {});
// The files' text, exactly as the writers above write it (for a writer that stores the file
// itself: the server journals it before writing). Same InputError checks.
std::string CameraFileText(const CameraIntrinsics& camera, const CalibrationSummary& summary);
// `inputs` (optional): written as the scene file's "points", "marks_m" and "table_z_m"; a
// non-finite value is an InputError naming it, before writing anything.
std::string SceneFileText(const SceneCalibration& scene, const CalibrationSummary& summary,
                          const SceneInputs& inputs = {});
// The same readers from a file's text; `path` names it in messages.
CameraIntrinsics ParseCameraFile(const std::string& path, const std::string& text);
SceneCalibration ParseSceneFile(const std::string& path, const std::string& text);
// What a scene file keeps of its inputs (empty when it keeps none). Throws InputError as
// ReadSceneFile does, also naming a point's key ("path.points[2].u_px") and the rule broken.
SceneInputs ReadSceneInputs(const std::string& path);
SceneInputs ParseSceneInputs(const std::string& path, const std::string& text);

}  // namespace uphill
