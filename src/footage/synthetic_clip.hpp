// Synthetic clips: video of the body rolling on the rails, rendered with exact ground truth, for
// the tests and the benchmark of the tracker (src/vision/ball_tracker.hpp) and for
// tools/make_video.
//
// What is drawn (apparatus frame of docs/physics.md "Frame and apparatus",
// metres): the body of a Scene (sphere or spheroid,
// symmetry axis along y) with its centre at (x, 0, z); the two rails as round rods whose axes are
// the rail lines (the scene's rod radius, or ClipApparatus::min_rod_radius when the scene has
// line rails or thinner rods, so they are visible), from O to a little beyond the crossbar; the
// crossbar, a horizontal round bar along y under the rails at x = crossbar_x; optionally the
// lab's marks (ClipApparatus: tape on the rods, the crossbar's feet, a ruler); a textured table
// (plane z = table_z) and a plain wall behind (plane y = wall_y). One directional light: Lambert
// shading with a Blinn–Phong highlight on the body and the rods, a soft shadow of the body on the
// table.
//
// How: inverse mapping. Every raw pixel's viewing ray (UndistortPixels, once per renderer) is
// intersected with the quadrics above. The static background is rendered once per renderer; a
// frame re-renders only the bounding box of the body and its shadow. Anti-aliasing: n×n
// supersampling, only for pixels near an object boundary (static edges found once, the body's
// outline per frame); the table texture is band-limited so the rest needs one sample. Motion blur:
// the average of `blur_samples` renders over the exposure.
//
// Ground truth (ClipTruth): at each frame's mid-exposure time t = frame/fps, the centre (x, z)
// from uphill::Motion, its raw-pixel projection (u, v) through camera.hpp (the same model the
// renderer inverts, so the truth is exact to the ray map's interpolation, < 1e-3 px), and the
// visible fraction of the body's outline (inside the frame, not hidden by a rod or the crossbar).
// Once the motion has ended (the body falls off or reaches O) the body is gone from the picture:
// present = false, as when a real ball drops out of view.
//
// Video files (RenderClip): ".mp4" is H.264 (fourcc 'avc1'), lossy; ".avi" and ".mkv" are FFV1,
// lossless (the no-noise accuracy tests use ".avi", whose container keeps timestamps exact).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "motion/motion.hpp"
#include "vision/camera.hpp"

namespace uphill {

struct ClipApparatus {
  double crossbar_x = 1.0;         // horizontal distance O -> crossbar, m
  double crossbar_radius = 0.010;  // m
  double min_rod_radius = 0.003;   // rods are drawn at least this thick, m
  double table_z = -0.03;          // height of the table, m (below O)
  double wall_y = 0.6;             // the wall behind the apparatus, m
  // The body's paint: glossy (Lambertian shading under a light from above, and a highlight),
  // matte (the shading alone) or flat (one colour, no shading: for testing the smear's geometry
  // and timing apart from the body's appearance).
  enum class Finish { kGlossy, kMatte, kFlat };
  Finish body_finish = Finish::kGlossy;
  // What a lab marks and a technician clicks (calibration/README.md, "The apparatus frame and the
  // points to use"); none by default. Black tape round both rods at these horizontal distances
  // from O (m); the crossbar's feet, round posts standing on the table under the rails; a yellow
  // ruler 30 mm wide on the table in front of the rails (its near edge at y = −160 mm), from
  // x = −20 mm to 1020 mm, a tick every 10 mm, x = 0 at O.
  std::vector<double> tape_marks_x;
  double tape_width = 0.008;   // m
  bool feet = false;
  double foot_radius = 0.004;  // m
  bool ruler = false;
};

// A ready-made setting: the default clip of tools/make_video and of the tests. Sphere of radius
// 25.4 mm on rods of 8 mm diameter, L = 1000 mm, H = 100 mm, D = 150 mm (X ≈ 314 mm); a camera
// on the near side (y < 0) looking across at the apparatus, which fills most of the frame;
// focal length scaled with the width (1300 px at 1280 wide), mild barrel distortion (k1 = −0.1,
// k2 = 0.02), principal point slightly off centre. The near rail hides the lower edge of the ball.
struct ClipSetup {
  Scene scene;
  SceneCalibration calibration;
  ClipApparatus apparatus;
  double x0;  // release position, m (released at rest below X: it rolls back toward O)
};
ClipSetup DefaultClipSetup(int width, int height);

// A trial of a video experiment (data/series3-video, `uphill bench report`): DefaultClipSetup with
// the rail separation D (m; L = 1 m, H = 0.1 m) and the release position x0 = band.high +
// f·(band.high − X) of the rest band of μ (f < 0: inside the band, the body stays; f > 0: beyond
// it, it rolls up and falls off). Throws InputError when the scene has no rest band for μ.
ClipSetup TrialClipSetup(int width, int height, double D, double mu, double band_fraction);

// The side-view camera of DefaultClipSetup for another scene, looking at (target_x, 0, target_z).
SceneCalibration SideViewCamera(int width, int height, double target_x, double target_z);

struct ClipSettings {
  int frames = 60;
  double fps = 30.0;
  double exposure = 1.0 / 120.0;  // s, shutter open time (used when blur_samples > 1)
  int blur_samples = 1;           // sub-exposure renders averaged; 1: a sharp frame
  int supersampling = 4;          // n: n×n samples per boundary pixel
  double noise_sigma = 0.0;       // Gaussian sensor noise, grey levels (8-bit), per channel
  double flicker = 0.0;           // relative standard deviation of a per-frame gain
  double release_time = 0.0;      // s: clip time of the release; at rest at x0 before it
  std::uint64_t seed = 1;         // noise and flicker
};

struct ClipTruth {
  int frame = 0;
  double t = 0;          // s, mid-exposure (the container's timestamp of the frame)
  bool present = false;  // the body is in the picture (false once the motion has ended)
  double x = 0, z = 0;   // centre, m
  double u = 0, v = 0;   // raw pixel of the centre
  double visibility = 0; // visible fraction of the outline, [0, 1]
};

class ClipRenderer {
 public:
  // Precomputes the ray map and the static background (a fraction of a second at 1280×720).
  // Throws InputError for a double cone (not drawn) or unusable intrinsics.
  ClipRenderer(const Scene& scene, const SceneCalibration& calibration, const ClipApparatus& apparatus,
               int supersampling = 4);
  ~ClipRenderer();
  ClipRenderer(const ClipRenderer&) = delete;
  ClipRenderer& operator=(const ClipRenderer&) = delete;

  // Linear colour (BGR, CV_32FC3, nominally [0, 1]) with the body at each of `centres` ((x, z),
  // m; several: motion blur, their average); empty: no body.
  cv::Mat RenderLinear(const std::vector<Eigen::Vector2d>& centres) const;
  // Visible fraction of the outline of the body centred at (x, 0, z).
  double Visibility(double x, double z) const;
  // Whether `point` (apparatus frame, m) is in plain view with the body at `centres` ((x, z), m):
  // its pixel is inside the image and the first surface its viewing ray meets is within `reach`
  // (m) of it. A mark on a rod's axis is seen on the rod's surface, one radius from the axis; a
  // point hidden behind a rod, the crossbar or the body is not seen.
  bool Sees(const Eigen::Vector3d& point, const std::vector<Eigen::Vector2d>& centres, double reach) const;
  const SceneCalibration& calibration() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// Renders the clip of `motion` (whose scene is the renderer's) into `video_path` (codec from the
// extension, see above) and returns the truth of every frame. Throws InputError for an unknown
// extension or bad settings, std::runtime_error when the file cannot be written.
std::vector<ClipTruth> RenderClip(const ClipRenderer& renderer, const Motion& motion, const ClipSettings& settings,
                                  const std::string& video_path);

// The 8-bit frame of a linear render as a camera writes it: gain, the sRGB transfer curve
// (sensor_model.hpp's SrgbEncode), then Gaussian noise of noise_sigma 8-bit levels, then rounding
// (what RenderClip writes).
cv::Mat ToFrame8(const cv::Mat& linear, double gain, double noise_sigma, cv::RNG& rng);

// Ground-truth CSV, header `frame,t,x,z,u,v,visibility` (t s, x z mm, u v raw px; x..v empty
// when the body is not present). Written atomically.
void WriteClipTruthCsv(const std::string& path, const std::vector<ClipTruth>& truth);

}  // namespace uphill
