// BallTracker: finds the body (sphere or spheroid) in the frames of a calibrated video, without
// clicks, and measures its centre to a small fraction of a pixel.
//
// Where it looks: only where the body can be. The first frame (and any frame after the body was
// lost) is searched along the projection of the scene's centre path x ↦ (x, 0, z(x)) for the
// predicted outline with the strongest, most consistent edge (TrackerOptions::init_uv, a raw pixel
// near the centre, replaces that search for the first frame). Then frame by frame near the
// prediction from the last positions (constant acceleration in the frame index).
//
// How it measures: the outline. Under perspective a sphere of radius R centred at C projects to
// the boundary of the cone of rays at the angle asin(R/|C − O|) about the direction of C − O (O the
// camera centre); its image is (nearly) an ellipse whose centre is not the projection of C. The
// tracker samples the grey values (of the region of interest only, lightly smoothed) along
// rays from the predicted centre across the predicted outline, locates each edge to sub-pixel
// (centroid of the gradient of the expected polarity above half its peak: the mid-exposure edge
// of a motion-blurred ball), undistorts the edge points to
// viewing rays, and fits with Ceres the centre C = (x, 0, z) in the plane y = 0: residual per edge
// point = angle between its ray and C − O minus the half angle, in pixels, under a Cauchy loss
// (highlights, the shadow, compression blocks and the crossbar give outliers that it ignores).
// A third, regularised parameter absorbs a uniform inward/outward bias of the edge detector
// (blur, limb darkening), so that the bias does not move the centre when part of the outline is
// hidden. The spheroid (symmetry axis along y): the same in the space where y is scaled by a/b,
// which maps it to a sphere of radius a and keeps tangency. Outline points behind the near
// rail's projected band are not used at all. (u, v) is the projection of the fitted C, which
// corrects the perspective shift of the ellipse centre for free.
//
// Accuracy (tests/vision_track_test.cpp, `uphill bench track`): on the synthetic clips of
// synthetic_clip.hpp (1280×720 view of a 1 m apparatus, ball radius ~25 px) RMS (u, v) error
// 0.03 px without blur and noise (tested ≤ 0.1 px), 0.06–0.08 px with motion blur, noise, flicker
// and H.264 (tested ≤ 0.3 px); (x, z) 0.03–0.09 mm (tested ≤ 0.5 mm). Cost per frame: measured by
// `uphill bench track` (docs/benchmarks.md). The camera and scene calibration's own errors add to these on real video.
//
// Hard cases: the near rail hides the lower edge (masked); the body leaves the frame or drops
// between the rails (lost: found = false, quality 0; the next frames search the whole path
// again); a frame with no ball anywhere (not found, never invented); a double cone (refused).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <opencv2/core.hpp>

#include "model/scene.hpp"
#include "vision/camera.hpp"

namespace uphill {

struct TrackerOptions {
  std::optional<Eigen::Vector2d> init_uv;  // raw pixel near the centre in the first frame
  int outline_points = 96;                 // edge searches per frame
  double search_half_width_px = 6;         // along each ray, either side of the predicted outline
  double min_inlier_fraction = 0.35;       // of the outline points; below: lost
  double rail_radius = 0.003;              // m: drawn width of line rails (scene without rods)
  double min_contrast = 12;                // grey levels across the outline to accept a body
};

struct BallObservation {
  bool found = false;
  double u = 0, v = 0;       // raw pixel of the fitted centre
  double radius_px = 0;      // mean distance of the outline from (u, v)
  double x = 0, z = 0;       // centre, m, apparatus frame
  double quality = 0;        // [0, 1]: inlier fraction × exp(−rms² / 2(0.5 px)²); 0 when not found
  int edge_points = 0, inliers = 0;
  double rms_px = 0;         // RMS residual of the inliers
};

class BallTracker {
 public:
  // Throws InputError for a double cone or unusable intrinsics.
  BallTracker(const Scene& scene, const SceneCalibration& calibration, const TrackerOptions& options = {});
  ~BallTracker();
  BallTracker(BallTracker&&) noexcept;

  // The next frame of the video (8-bit BGR or grey, the calibration's size; InputError otherwise).
  BallObservation Track(const cv::Mat& frame);

  // The raw-pixel outline of a body centred at (x, 0, z) (n points), e.g. to draw it.
  std::vector<Eigen::Vector2d> Outline(double x, double z, int n) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace uphill
