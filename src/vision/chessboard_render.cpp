#include "vision/chessboard_render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "model/input_error.hpp"

namespace uphill {
namespace {

constexpr double kDegree = std::numbers::pi / 180;

// Grey level of the board point (x, y) (board frame, metres): squares, white margin, or the
// background beyond it.
struct BoardPainter {
  const ChessboardTarget& target;
  const ChessboardRenderOptions& options;

  double operator()(double x, double y) const {
    const double s = target.square;
    const double margin = options.margin_squares * s;
    // Squares cover [−s, cols·s] × [−s, rows·s]: the inner corners are at multiples of s.
    if (x < -s - margin || y < -s - margin || x > target.cols * s + margin || y > target.rows * s + margin)
      return options.background;
    if (x < -s || y < -s || x > target.cols * s || y > target.rows * s) return options.white;
    const long i = static_cast<long>(std::floor(x / s)), j = static_cast<long>(std::floor(y / s));
    return (i + j) % 2 == 0 ? options.black : options.white;  // the outer corner squares are black
  }
};

// The board outline with its margin, sampled along the edges (distortion bends straight edges).
std::vector<Eigen::Vector3d> OutlinePoints(const ChessboardTarget& target, double margin_squares) {
  const double s = target.square, m = margin_squares * s;
  const double x0 = -s - m, x1 = target.cols * s + m, y0 = -s - m, y1 = target.rows * s + m;
  std::vector<Eigen::Vector3d> out;
  constexpr int kPerEdge = 12;
  for (int k = 0; k <= kPerEdge; ++k) {
    const double a = static_cast<double>(k) / kPerEdge;
    out.emplace_back(x0 + a * (x1 - x0), y0, 0);
    out.emplace_back(x0 + a * (x1 - x0), y1, 0);
    out.emplace_back(x0, y0 + a * (y1 - y0), 0);
    out.emplace_back(x1, y0 + a * (y1 - y0), 0);
  }
  return out;
}

}  // namespace

void ValidateTarget(const ChessboardTarget& target) {
  if (target.cols < 2 || target.cols > 100)
    throw InputError("--cols", "must be 2 to 100 inner corners (got " + std::to_string(target.cols) + ")");
  if (target.rows < 2 || target.rows > 100)
    throw InputError("--rows", "must be 2 to 100 inner corners (got " + std::to_string(target.rows) + ")");
  RequirePositiveFinite("--square", target.square);
}

std::vector<Eigen::Vector3d> ChessboardCorners(const ChessboardTarget& target) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<size_t>(target.cols) * target.rows);
  for (int r = 0; r < target.rows; ++r)
    for (int c = 0; c < target.cols; ++c) out.emplace_back(c * target.square, r * target.square, 0);
  return out;
}

ChessboardRenderer::ChessboardRenderer(const CameraIntrinsics& camera, const ChessboardTarget& target)
    : camera_(camera), target_(target) {
  ValidateIntrinsics(camera_, "camera");
  ValidateTarget(target_);
  std::vector<Eigen::Vector2d> pixel_corners;
  pixel_corners.reserve(static_cast<size_t>(camera_.width + 1) * (camera_.height + 1));
  for (int v = 0; v <= camera_.height; ++v)
    for (int u = 0; u <= camera_.width; ++u) pixel_corners.emplace_back(u - 0.5, v - 0.5);
  corner_rays_ = UndistortPixels(camera_, pixel_corners);
}

ChessboardView ChessboardRenderer::Render(const CameraPose& board_pose,
                                          const ChessboardRenderOptions& options) const {
  if (options.supersampling < 1 || options.supersampling > 16)
    throw InputError("supersampling", "must be 1 to 16 (got " + std::to_string(options.supersampling) + ")");
  if (!(options.blur_sigma_px >= 0 && options.blur_sigma_px <= 50))
    throw InputError("blur", "must be 0 to 50 px");
  if (!(options.noise_sigma >= 0 && options.noise_sigma <= 255)) throw InputError("noise", "must be 0 to 255");
  if (!(options.margin_squares >= 0 && options.margin_squares <= 10))
    throw InputError("margin", "must be 0 to 10 squares");

  ChessboardView view;
  view.board_pose = board_pose;
  view.corners = ProjectApparatusPoints(camera_, board_pose, ChessboardCorners(target_));

  // A ray λ·d (d = (x, y, 1)) meets the board plane n·(λ·d − t) = 0 at λ = n·t / n·d, n the
  // board's normal in the camera frame; the board coordinates are then the first two rows of
  // Rᵀ(λ·d − t).
  const Eigen::Matrix3d& r = board_pose.rotation;
  const Eigen::Vector3d& t = board_pose.translation;
  const Eigen::Vector3d ex = r.col(0), ey = r.col(1), n = r.col(2);
  const double n_t = n.dot(t);
  const BoardPainter paint{target_, options};

  const int s = options.supersampling, w = camera_.width, h = camera_.height;
  cv::Mat grey(h, w, CV_32F);
  for (int v = 0; v < h; ++v) {
    float* row = grey.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d& r00 = corner_rays_[static_cast<size_t>(v) * (w + 1) + u];
      const Eigen::Vector2d& r10 = corner_rays_[static_cast<size_t>(v) * (w + 1) + u + 1];
      const Eigen::Vector2d& r01 = corner_rays_[static_cast<size_t>(v + 1) * (w + 1) + u];
      const Eigen::Vector2d& r11 = corner_rays_[static_cast<size_t>(v + 1) * (w + 1) + u + 1];
      double sum = 0;
      for (int j = 0; j < s; ++j) {
        const double b = (j + 0.5) / s;
        const Eigen::Vector2d left = (1 - b) * r00 + b * r01, right = (1 - b) * r10 + b * r11;
        for (int i = 0; i < s; ++i) {
          const double a = (i + 0.5) / s;
          const Eigen::Vector2d ray = (1 - a) * left + a * right;
          const Eigen::Vector3d d(ray.x(), ray.y(), 1);
          const double n_d = n.dot(d);
          const double lambda = n_d != 0 ? n_t / n_d : -1;
          if (!(lambda > 0)) {  // the ray misses the board's plane (or meets it behind the camera)
            sum += options.background;
            continue;
          }
          const Eigen::Vector3d p = lambda * d - t;
          sum += paint(ex.dot(p), ey.dot(p));
        }
      }
      row[u] = static_cast<float>(sum / (s * s));
    }
  }
  if (options.blur_sigma_px > 0) cv::GaussianBlur(grey, grey, cv::Size(0, 0), options.blur_sigma_px);
  if (options.noise_sigma > 0) {
    std::mt19937 rng(options.seed);
    std::normal_distribution<float> noise(0, static_cast<float>(options.noise_sigma));
    for (int v = 0; v < h; ++v) {
      float* row = grey.ptr<float>(v);
      for (int u = 0; u < w; ++u) row[u] += noise(rng);
    }
  }
  grey.convertTo(view.image, CV_8U);  // rounds and saturates to 0..255
  return view;
}

std::vector<CameraPose> RandomBoardPoses(const CameraIntrinsics& camera, const ChessboardTarget& target,
                                         int count, std::uint32_t seed,
                                         const RandomBoardPoseOptions& options) {
  ValidateIntrinsics(camera, "camera");
  ValidateTarget(target);
  if (count < 0) throw InputError("count", "must be ≥ 0");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  const double s = target.square, m = options.margin_squares * s;
  const double board_width = (target.cols + 1) * s + 2 * m, board_height = (target.rows + 1) * s + 2 * m;
  const Eigen::Vector3d board_centre((target.cols - 1) * s / 2, (target.rows - 1) * s / 2, 0);
  const std::vector<Eigen::Vector3d> outline = OutlinePoints(target, options.margin_squares);

  std::vector<CameraPose> poses;
  for (int view = 0; view < count; ++view) {
    const int cell_x = view % 3, cell_y = (view / 3) % 3;
    bool placed = false;
    for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
      const double size = options.min_size + unit(rng) * (options.max_size - options.min_size);
      const double distance = camera.fx * board_width / (size * camera.width);
      // Where the board's centre may go so that it stays inside (fronto-parallel estimate; the
      // exact check below rejects what tilt and distortion push out).
      const double half_u = size * camera.width / 2 + options.margin_px;
      const double half_v = camera.fy * board_height / distance / 2 + options.margin_px;
      const double lo_u = std::min(half_u, camera.width / 2.0), hi_u = std::max(camera.width - half_u, camera.width / 2.0);
      const double lo_v = std::min(half_v, camera.height / 2.0), hi_v = std::max(camera.height - half_v, camera.height / 2.0);
      const Eigen::Vector2d centre_px(lo_u + (cell_x + unit(rng)) / 3 * (hi_u - lo_u),
                                      lo_v + (cell_y + unit(rng)) / 3 * (hi_v - lo_v));
      const double tilt = (options.min_tilt_deg + unit(rng) * (options.max_tilt_deg - options.min_tilt_deg)) * kDegree;
      const double axis_angle = unit(rng) * 2 * std::numbers::pi;
      const double spin = (2 * unit(rng) - 1) * options.max_spin_deg * kDegree;
      CameraPose pose;
      pose.rotation = (Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(axis_angle), std::sin(axis_angle), 0)) *
                       Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()))
                          .toRotationMatrix();
      const Eigen::Vector2d ray = UndistortPixel(camera, centre_px);
      pose.translation = distance * Eigen::Vector3d(ray.x(), ray.y(), 1) - pose.rotation * board_centre;
      bool inside = true;
      for (const auto& p : outline)
        if ((pose.rotation * p + pose.translation).z() < 0.1 * distance) inside = false;
      if (!inside) continue;
      for (const auto& q : ProjectApparatusPoints(camera, pose, outline))
        if (q.x() < options.margin_px || q.y() < options.margin_px || q.x() > camera.width - 1 - options.margin_px ||
            q.y() > camera.height - 1 - options.margin_px)
          inside = false;
      if (!inside) continue;
      poses.push_back(pose);
      placed = true;
    }
    if (!placed)
      throw InputError("board poses", "the board (" + std::to_string(board_width * 1000) + " mm wide with margin) " +
                                          "cannot be placed inside the image at the requested sizes and tilts");
  }
  return poses;
}

}  // namespace uphill
