#include "vision/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "model/input_error.hpp"
#include "vision/decode_limits.hpp"
#include "vision/library_logs.hpp"

namespace uphill {
namespace {

constexpr double kDegree = std::numbers::pi / 180;
constexpr int kCoverageCells = 5;  // the coverage grid is kCoverageCells × kCoverageCells

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

cv::Mat Grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Matx33d CameraMatrix(const CameraIntrinsics& c) { return cv::Matx33d(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1); }

Eigen::Matrix3d RotationOf(const cv::Mat& rvec) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = r(i, j);
  return out;
}

// The ratio of the second to the first singular value of the centred points: 0 for points on
// one line, ~1 for points spread evenly in (at least) two directions.
template <int N>
double Flatness(const std::vector<Eigen::Matrix<double, N, 1>>& points) {
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), N);
  for (size_t i = 0; i < points.size(); ++i) centred.row(static_cast<Eigen::Index>(i)) = (points[i] - mean).transpose();
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  return s(0) > 0 ? s(1) / s(0) : 0;
}

// The pose fitted to `points` without the one at `skip` (skip ≥ size: all of them): SQPnP, then
// Levenberg-Marquardt. nullopt when no pose fits.
std::optional<CameraPose> FitPose(const CameraIntrinsics& camera, const std::vector<ScenePoint>& points, size_t skip) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < points.size(); ++i) {
    if (i == skip) continue;
    object.emplace_back(points[i].position.x(), points[i].position.y(), points[i].position.z());
    image.emplace_back(points[i].pixel.x(), points[i].pixel.y());
  }
  cv::Mat dist = camera.distortion.empty() ? cv::Mat() : cv::Mat(camera.distortion, true);
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, image, CameraMatrix(camera), dist, rvec, tvec, false, cv::SOLVEPNP_SQPNP)) return std::nullopt;
  cv::solvePnPRefineLM(object, image, CameraMatrix(camera), dist, rvec, tvec,
                       cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-12));
  CameraPose pose;
  pose.rotation = RotationOf(rvec);
  pose.translation = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return pose;
}

// Throws InputError(quantity) unless lo ≤ value ≤ hi (metres), naming the value and the range in mm.
void RequireLengthIn(const std::string& quantity, double value, double lo, double hi, const std::string& why) {
  if (value >= lo && value <= hi) return;
  const auto mm = [](double v) {
    std::ostringstream out;
    out << v * 1000;
    return out.str() + " mm";
  };
  throw InputError(quantity, mm(value) + " is outside the allowed range " + mm(lo) + " to " + mm(hi) + " (" + why + ")");
}

}  // namespace

void ValidateCalibrationTarget(const ChessboardTarget& target, const std::string& square_name) {
  ValidateTarget(target);
  RequireLengthIn(square_name, target.square, kMinSquare, kMaxSquare, "the side of one printed square");
}

// ---- corners ----

std::vector<Eigen::Vector2d> FindChessboardCorners(const cv::Mat& image, const ChessboardTarget& target) {
  ValidateTarget(target);
  const cv::Mat grey = Grey(image);
  const cv::Size pattern(target.cols, target.rows);
  // The sector-based detector (findChessboardCornersSB): the classic findChessboardCorners can take
  // minutes on a view when --cols/--rows are one too small (its quad linking explodes), while
  // SB takes under a second on any image. It first runs at half resolution (4× faster), then at full
  // resolution for boards too small to be found there. cornerSubPix refines at full resolution.
  std::vector<cv::Point2f> corners;
  bool found = false;
  if (grey.cols >= 1000) {
    cv::Mat half;
    cv::pyrDown(grey, half);
    found = cv::findChessboardCornersSB(half, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
    for (auto& p : corners) p *= 2.f;  // pyrDown's pixel i is centred on the input's pixel 2i
  }
  if (!found) found = cv::findChessboardCornersSB(grey, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found) return {};
  // The refinement window must stay within one square: 0.4 × the smallest corner spacing.
  double spacing = 1e9;
  for (int r = 0; r < target.rows; ++r)
    for (int c = 0; c + 1 < target.cols; ++c)
      spacing = std::min<double>(spacing, cv::norm(corners[r * target.cols + c + 1] - corners[r * target.cols + c]));
  const int half_window = std::clamp(static_cast<int>(0.4 * spacing), 2, 11);
  cv::cornerSubPix(grey, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-4));
  std::vector<Eigen::Vector2d> out;
  out.reserve(corners.size());
  for (const auto& p : corners) out.emplace_back(p.x, p.y);
  // The detectors may start at any of the board's four outer corners. First the handedness: on
  // the printed side, rows run right and columns down (as on the sheet, ChessboardTargetImage), so
  // (corner 1 − corner 0) × (corner cols − corner 0) > 0 in the image; a negative sign means the
  // rows were listed bottom to top: take them in the reverse order.
  const size_t cols = static_cast<size_t>(target.cols), rows = static_cast<size_t>(target.rows);
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  if (cross(out[1] - out[0], out[cols] - out[0]) < 0)
    for (size_t r = 0; r < rows / 2; ++r)
      std::swap_ranges(out.begin() + r * cols, out.begin() + (r + 1) * cols, out.begin() + (rows - 1 - r) * cols);
  // Then the turn by 180°: with cols + rows odd the square diagonally outside the first corner is
  // black, the one outside the last corner white (the two ends are told apart by colour).
  if ((target.cols + target.rows) % 2 == 1) {
    const auto outside = [&](size_t corner, size_t along_row, size_t along_column) {
      const Eigen::Vector2d p = out[corner] + 0.5 * ((out[corner] - out[along_row]) + (out[corner] - out[along_column]));
      const int u = std::clamp(static_cast<int>(std::lround(p.x())), 0, grey.cols - 1);
      const int v = std::clamp(static_cast<int>(std::lround(p.y())), 0, grey.rows - 1);
      return static_cast<double>(grey.at<uchar>(v, u));
    };
    const size_t last = out.size() - 1;
    if (outside(0, 1, cols) > outside(last, last - 1, last - cols)) std::reverse(out.begin(), out.end());
  }
  return out;
}

// ---- camera ----

CameraCalibration CalibrateCamera(const std::vector<NamedImage>& images, const ChessboardTarget& target,
                                  const CameraCalibrationOptions& options) {
  ValidateCalibrationTarget(target);
  if (images.empty()) throw InputError("images", "none given: give 10 to 20 views of the chessboard");
  const cv::Size size = images.front().image.size();
  for (const auto& view : images) {
    if (view.image.empty()) throw InputError(view.name, "is an empty image");
    if (view.image.depth() != CV_8U) throw InputError(view.name, "must be an 8-bit image");
    if (view.image.size() != size)
      throw InputError(view.name, "is " + std::to_string(view.image.cols) + "×" + std::to_string(view.image.rows) +
                                      " pixels, but " + images.front().name + " is " + std::to_string(size.width) +
                                      "×" + std::to_string(size.height) + ": all views must come from one camera setting");
  }
  // The same picture twice (a file given twice, or copied) would count as two views and make the
  // fit look better constrained than it is.
  for (size_t i = 1; i < images.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (images[i].image.channels() == images[k].image.channels() && cv::norm(images[i].image, images[k].image, cv::NORM_INF) == 0)
        throw InputError(images[i].name, "is the same image as " + images[k].name +
                                             ": each view must be a new photograph (move or tilt the board between shots)");

  CameraCalibration result;
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<size_t> used;  // indices into images
  std::vector<cv::Point3f> board;
  for (const auto& p : ChessboardCorners(target))
    board.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
  for (size_t i = 0; i < images.size(); ++i) {
    ViewDiagnostics d;
    d.name = images[i].name;
    const std::vector<Eigen::Vector2d> corners = FindChessboardCorners(images[i].image, target);
    if (corners.empty()) {
      d.rejected_because = "the " + std::to_string(target.cols) + "×" + std::to_string(target.rows) +
                           " inner corners were not found (whole board in view, sharp, --cols/--rows right?)";
    } else {
      std::vector<cv::Point2f> points;
      for (const auto& c : corners) points.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
      image_points.push_back(points);
      object_points.push_back(board);
      used.push_back(i);
      d.used = true;
    }
    result.views.push_back(d);
  }
  if (used.size() < 3) {
    std::string names;
    for (const auto& d : result.views)
      if (!d.used) names += (names.empty() ? "" : ", ") + d.name;
    throw InputError(used.empty() ? images.front().name : "images",
                     "the chessboard was found in only " + std::to_string(used.size()) + " of " +
                         std::to_string(images.size()) + " images (at least 3 needed, 10 to 20 advised); " +
                         "not found in: " + names);
  }

  cv::Mat k, dist, std_intrinsics, std_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  int flags = options.fit_k3 ? 0 : cv::CALIB_FIX_K3;
  result.rms_px = cv::calibrateCamera(object_points, image_points, size, k, dist, rvecs, tvecs, std_intrinsics,
                                      std_extrinsics, per_view, flags,
                                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  CameraIntrinsics& c = result.camera;
  c.width = size.width;
  c.height = size.height;
  c.fx = k.at<double>(0, 0);
  c.fy = k.at<double>(1, 1);
  c.cx = k.at<double>(0, 2);
  c.cy = k.at<double>(1, 2);
  c.distortion.assign(dist.begin<double>(), dist.begin<double>() + std::min<int>(5, static_cast<int>(dist.total())));
  for (int j = 0; j < 4; ++j) result.std_dev_px(j) = std_intrinsics.at<double>(j);
  result.views_used = static_cast<int>(used.size());

  std::vector<bool> cells(kCoverageCells * kCoverageCells, false);
  int tilted = 0;
  for (size_t n = 0; n < used.size(); ++n) {
    ViewDiagnostics& d = result.views[used[n]];
    d.rms_px = per_view.at<double>(static_cast<int>(n));
    const Eigen::Matrix3d r = RotationOf(rvecs[n]);
    d.tilt_deg = std::acos(std::min(1.0, std::abs(r(2, 2)))) / kDegree;
    d.distance_m = cv::norm(tvecs[n]);
    if (d.tilt_deg >= options.min_tilt_deg) ++tilted;
    for (const auto& p : image_points[n]) {
      const int cu = std::clamp(static_cast<int>(p.x * kCoverageCells / size.width), 0, kCoverageCells - 1);
      const int cv_ = std::clamp(static_cast<int>(p.y * kCoverageCells / size.height), 0, kCoverageCells - 1);
      cells[cv_ * kCoverageCells + cu] = true;
    }
  }
  result.coverage = static_cast<double>(std::count(cells.begin(), cells.end(), true)) / cells.size();

  auto& why = result.reasons;
  if (result.views_used < options.min_good_views)
    why.push_back("only " + std::to_string(result.views_used) + " usable views (" +
                  std::to_string(options.min_good_views) + " or more advised, 15 to 20 best)");
  if (result.rms_px > options.max_good_rms_px)
    why.push_back("RMS reprojection error " + Fixed(result.rms_px, 3) + " px is above " +
                  Fixed(options.max_good_rms_px, 1) + " px (blurred views, a board that is not flat, wrong --square?)");
  if (result.coverage < options.min_coverage)
    why.push_back("the corners cover only " + Fixed(100 * result.coverage, 0) + " % of the image (cells of a " +
                  std::to_string(kCoverageCells) + "×" + std::to_string(kCoverageCells) +
                  " grid): show the board near the edges and in the corners too, where the distortion is largest");
  if (tilted < 3)
    why.push_back("only " + std::to_string(tilted) + " views with the board tilted by " +
                  Fixed(options.min_tilt_deg, 0) + "° or more: with the board always nearly parallel to the " +
                  "image the focal length and the distance cannot be told apart; tilt it 20–45° in various directions");
  for (size_t n = 0; n < used.size(); ++n) {
    const ViewDiagnostics& d = result.views[used[n]];
    if (d.rms_px > 3 * result.rms_px && d.rms_px > 0.5)
      why.push_back(d.name + ": its RMS error " + Fixed(d.rms_px, 2) + " px is far above the others' (motion blur?" +
                    " leave it out and calibrate again)");
  }
  result.verdict = why.empty() ? "good" : "poor";
  return result;
}

CameraCalibration CalibrateCameraFromFiles(const std::vector<std::string>& paths, const ChessboardTarget& target,
                                           const CameraCalibrationOptions& options) {
  ValidateCalibrationTarget(target);
  for (const auto& path : paths) CheckImagePixels(path, path);
  std::vector<NamedImage> images;
  QuietVideoLibraryLogs();
  for (const auto& path : paths) {
    cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw InputError(path, "cannot be read as an image (missing, or not PNG/JPEG/…)");
    images.push_back({path, image});
  }
  return CalibrateCamera(images, target, options);
}

CalibrationSummary CameraCalibration::Summary(const ChessboardTarget& target) const {
  CalibrationSummary s;
  s.method = "chessboard, " + std::to_string(target.cols) + "×" + std::to_string(target.rows) +
             " inner corners, " + Fixed(target.square * 1000, 3) + " mm squares; OpenCV calibrateCamera";
  s.rms_px = rms_px;
  s.verdict = verdict;
  s.reasons = reasons;
  for (const auto& d : views)
    s.inputs.push_back(d.used ? d.name + ": used, RMS " + Fixed(d.rms_px, 3) + " px, tilt " + Fixed(d.tilt_deg, 1) +
                                    "°, distance " + Fixed(d.distance_m * 1000, 0) + " mm"
                              : d.name + ": rejected, " + d.rejected_because);
  return s;
}

// ---- scene ----

SceneCalibrationResult CalibrateScene(const CameraIntrinsics& camera, const std::vector<ScenePoint>& points,
                                      int frame_width, int frame_height) {
  ValidateIntrinsics(camera, "camera");
  if ((frame_width > 0 || frame_height > 0) && (frame_width != camera.width || frame_height != camera.height))
    throw InputError("frame", "is " + std::to_string(frame_width) + "×" + std::to_string(frame_height) +
                                  " pixels but the camera was calibrated at " + std::to_string(camera.width) + "×" +
                                  std::to_string(camera.height) + ": film at the calibrated resolution");
  if (points.size() < 4)
    throw InputError("points", "at least 4 are needed, 6 or more advised (got " + std::to_string(points.size()) + ")");
  for (size_t i = 0; i < points.size(); ++i) {
    const ScenePoint& p = points[i];
    if (!p.pixel.allFinite() || !p.position.allFinite()) throw InputError(p.label, "must be finite");
    for (int k = 0; k < 3; ++k)
      RequireLengthIn(p.label + ": " + "xyz"[k], p.position[k], -kMaxPointDistance, kMaxPointDistance,
                      "an apparatus point's coordinate, from O");
    if (p.pixel.x() < -0.5 || p.pixel.y() < -0.5 || p.pixel.x() > camera.width - 0.5 ||
        p.pixel.y() > camera.height - 0.5)
      throw InputError(p.label, "pixel (" + Fixed(p.pixel.x(), 1) + ", " + Fixed(p.pixel.y(), 1) +
                                    ") is outside the camera's " + std::to_string(camera.width) + "×" +
                                    std::to_string(camera.height) + " image");
    for (size_t j = 0; j < i; ++j)
      if ((points[j].position - p.position).norm() < 1e-6)
        throw InputError(p.label, "has the same position as " + points[j].label);
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : points) {
    positions.push_back(p.position);
    pixels.push_back(p.pixel);
  }
  const double flatness = Flatness(positions);
  if (flatness < 1e-3)
    throw InputError("points", "all lie on one line in the apparatus: the rotation about that line is undetermined; "
                               "add points off the line (e.g. both rails at the crossbar and O)");
  if (Flatness(pixels) < 1e-3)
    throw InputError("points", "their pixels all lie on one line: the camera sees them edge-on; "
                               "film from higher up or add points off that plane");

  const std::optional<CameraPose> pose = FitPose(camera, points, points.size());
  if (!pose) throw InputError("points", "no camera pose fits them (check that each pixel belongs to its point)");
  SceneCalibrationResult result;
  result.scene.camera = camera;
  result.scene.pose = *pose;
  // Leave-one-out: the pose refitted without each point in turn. A misread point pulls the full
  // fit toward itself, so its own residual can be smaller than a good neighbour's; the pose
  // without it does not, so removing it lowers the RMS error of the others most.
  struct Without {
    bool in_front = false;  // every other point in front of the camera in the pose without it
    double residual_px = 0, rms_px = 0;
  };
  std::vector<std::optional<Without>> without(points.size());
  if (points.size() >= kMinPointsForLeaveOneOut)
    for (size_t i = 0; i < points.size(); ++i) {
      const std::optional<CameraPose> pose_without = FitPose(camera, points, i);
      if (!pose_without) continue;
      Without w;
      w.in_front = true;
      double sum = 0;
      for (size_t k = 0; k < points.size(); ++k) {
        const bool in_front = (pose_without->rotation * points[k].position + pose_without->translation).z() > 0;
        // A point behind the camera has no pixel: infinitely far from its click.
        const double e = in_front ? (ProjectApparatusPoint(camera, *pose_without, points[k].position) - points[k].pixel).norm()
                                  : std::numeric_limits<double>::infinity();
        if (k == i) {
          w.residual_px = e;
        } else {
          w.in_front = w.in_front && in_front;
          sum += e * e;
        }
      }
      w.rms_px = std::sqrt(sum / static_cast<double>(points.size() - 1));
      without[i] = w;
    }
  // How far a point lies from where the others place it, in words (behind the camera: no pixel).
  const auto from_others = [](double px) -> std::string {
    return std::isfinite(px) ? Fixed(px, 1) + " px from where the other points place it"
                             : "behind the camera in the pose the other points give";
  };
  // The point whose removal leaves the smallest RMS error (the largest drop).
  std::optional<size_t> lowest;
  for (size_t i = 0; i < points.size(); ++i)
    if (without[i] && without[i]->in_front && (!lowest || without[i]->rms_px < without[*lowest]->rms_px)) lowest = i;
  if (lowest) {
    result.leave_one_out = LeaveOneOutCheck{*lowest, points[*lowest].label, without[*lowest]->residual_px,
                                            without[*lowest]->rms_px, false};
  }
  for (size_t i = 0; i < points.size(); ++i)
    if ((result.scene.pose.rotation * points[i].position + result.scene.pose.translation).z() <= 0) {
      if (lowest && without[*lowest]->residual_px > kLeaveOneOutMinResidualPx)
        throw InputError(points[*lowest].label,
                         "does not fit the other points (it lies " + from_others(without[*lowest]->residual_px) +
                             "), and with it " + points[i].label +
                             " would lie behind the camera: check this point's pixel and position");
      throw InputError(points[i].label, "lies behind the camera in the best-fitting pose: the points and pixels disagree");
    }
  const std::vector<Eigen::Vector2d> reprojected = ProjectApparatusPoints(camera, result.scene.pose, positions);
  double sum = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double e = (reprojected[i] - points[i].pixel).norm();
    result.residuals.push_back({points[i].label, e});
    sum += e * e;
  }
  result.rms_px = std::sqrt(sum / points.size());

  auto& why = result.reasons;
  if (points.size() < 6)
    why.push_back("only " + std::to_string(points.size()) +
                  " points: with 6 or more a mistyped or misread point shows as a large residual");
  if (result.rms_px > 2)
    why.push_back("RMS reprojection error " + Fixed(result.rms_px, 2) +
                  " px is above 2 px: a point misread or mismeasured, or the camera file is not this camera's");
  if (flatness < 0.05)
    why.push_back("the points lie nearly on one line: the rotation about it is poorly determined");
  if (result.leave_one_out) {
    LeaveOneOutCheck& check = *result.leave_one_out;
    check.explains = check.residual_px > kLeaveOneOutMinResidualPx && check.rms_without_px <= 0.5 * result.rms_px;
    if (check.explains)
      why.push_back(check.label + ": " + from_others(check.residual_px) + "; without it the RMS error falls from " +
                    Fixed(result.rms_px, 2) + " to " + Fixed(check.rms_without_px, 2) + " px (check this point)");
    else if (result.rms_px > 2)
      why.push_back("no single point explains the error: without any one of them the RMS error stays at " +
                    Fixed(check.rms_without_px, 2) + " px or more (several points off, or the wrong camera file)");
  }
  result.verdict = why.empty() ? "good" : "poor";
  return result;
}

CalibrationSummary SceneCalibrationResult::Summary() const {
  CalibrationSummary s;
  s.method = "points of known position, OpenCV solvePnP (SQPnP) + Levenberg-Marquardt refinement";
  s.rms_px = rms_px;
  s.verdict = verdict;
  s.reasons = reasons;
  for (const auto& r : residuals) s.inputs.push_back(r.label + ": residual " + Fixed(r.error_px, 3) + " px");
  return s;
}

SceneCalibrationResult CalibrateSceneFromChessboard(const CameraIntrinsics& camera, const NamedImage& image,
                                                    const ChessboardTarget& target, const Eigen::Vector3d& origin,
                                                    const Eigen::Vector3d& x_axis, const Eigen::Vector3d& y_axis) {
  ValidateCalibrationTarget(target);
  if ((target.cols + target.rows) % 2 == 0)
    throw InputError("--cols/--rows", "a board with cols + rows even looks the same turned by 180°, so its origin "
                                      "is ambiguous: use e.g. 9×6 inner corners");
  if (!origin.allFinite() || std::abs(x_axis.norm() - 1) > 1e-6 || std::abs(y_axis.norm() - 1) > 1e-6 ||
      std::abs(x_axis.dot(y_axis)) > 1e-6)
    throw InputError("board axes", "must be orthogonal unit vectors");
  if (image.image.cols != camera.width || image.image.rows != camera.height)
    throw InputError(image.name, "is " + std::to_string(image.image.cols) + "×" + std::to_string(image.image.rows) +
                                     " pixels but the camera was calibrated at " + std::to_string(camera.width) +
                                     "×" + std::to_string(camera.height));
  const std::vector<Eigen::Vector2d> corners = FindChessboardCorners(image.image, target);
  if (corners.empty())
    throw InputError(image.name, "the " + std::to_string(target.cols) + "×" + std::to_string(target.rows) +
                                     " inner corners of the chessboard were not found");
  std::vector<ScenePoint> points;
  const std::vector<Eigen::Vector3d> board = ChessboardCorners(target);
  for (size_t i = 0; i < board.size(); ++i)
    points.push_back({image.name + ", corner " + std::to_string(i), corners[i],
                      origin + board[i].x() * x_axis + board[i].y() * y_axis});
  return CalibrateScene(camera, points, image.image.cols, image.image.rows);
}

cv::Mat ChessboardTargetImage(const ChessboardTarget& target, int pixels_per_square) {
  ValidateTarget(target);
  if (pixels_per_square < 4 || pixels_per_square > 1000)
    throw InputError("pixels per square", "must be 4 to 1000");
  const int squares_x = target.cols + 1, squares_y = target.rows + 1, p = pixels_per_square;
  cv::Mat image((squares_y + 2) * p, (squares_x + 2) * p, CV_8U, cv::Scalar(255));
  for (int j = 0; j < squares_y; ++j)
    for (int i = 0; i < squares_x; ++i)
      if ((i + j) % 2 == 0) image(cv::Rect((i + 1) * p, (j + 1) * p, p, p)).setTo(0);  // black corner squares
  return image;
}

}  // namespace uphill
