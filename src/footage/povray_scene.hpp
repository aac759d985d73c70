// POV-Ray scene of the apparatus: the scene description language (SDL) text that POV-Ray 3.7
// renders for the physically based test footage (footage_clip.hpp). Independent of the tracker
// and of synthetic_clip.hpp: only the geometry (Scene, camera.hpp) is shared.
//
// What is drawn, in the apparatus frame of docs/physics.md "Frame and apparatus" (O the rails'
// meeting point, x along the centre line, y across, z up), in millimetres (POV-Ray's intersection tolerances are absolute,
// ~1e-6 units: metres would bring them near the size of a pixel's footprint on a rod):
//  - the table: the plane z = table_z as a slab, wood (POV-Ray's `wood` rings along x with
//    turbulence, fine grain noise, a satin finish with a faint reflection), cloth (a woven
//    gingham: crossing stripes, a fibre bump map, matte), paper or tiles (TableCover);
//  - a painted wall behind the apparatus (plane y = wall_y);
//  - the rails: round rods whose axes are the rail lines (the Scene's rod radius: 8 mm rods, or
//    wires of ≤ 1 mm), polished steel with mirror reflection (or painted: rod_rgb), from O to a little beyond the
//    crossbar, with black tape marks at the positions of FootageApparatus::marks; the crossbar (a
//    horizontal bar along y under the rails at x = L) on two posts standing on the table under
//    the rails;
//  - the body: a sphere or the spheroid (semi-axes a in x and z, b along the rolling axis y),
//    painted plastic (BodyFinish), optionally with a painted band: the slab |z'| < band half width
//    of the body's own frame, which contains the rolling axis, so the band turns with the body (its
//    inner edges move across the disc as it rolls), and a pattern (BodyPattern). Placed at
//    (x, 0, z) and turned by the rolling angle about +y (right-handed: MotionSample::angle);
//  - lights: a square area light (soft box, 0.5 m) 1 m above the table, which casts soft
//    shadows beside the body, a dim shadowless fill from the camera's side, and any lamps;
//  - for the camera calibration: a chessboard target (white board, black squares) at a pose.
//
// The camera: a pinhole (POV-Ray `perspective`) whose rays are exactly those of the OpenCV
// pinhole camera K = [fx 0 cx; 0 fy cy; 0 0 1] with the given pose, for the pixels of `crop` (a
// window of that camera's image, so that a small region is rendered as its own small image). The
// POV-Ray ray of output pixel (i, j) of a W × H image is direction + ((i + ½)/W − ½)·right +
// (½ − (j + ½)/H)·up (POV-Ray 3.7 samples pixel centres; checked against cv::projectPoints by
// tests/vision_povray_test.cpp to < 0.01 px), so with right = (W/fx)·X, up = −(H/fy)·Y and
// direction = Z + ((crop.x + W/2 − ½ − cx)/fx)·X + ((crop.y + H/2 − ½ − cy)/fy)·Y (X, Y, Z the
// camera axes in the apparatus frame) output pixel (i, j) is OpenCV pixel (crop.x + i, crop.y + j).
// POV-Ray's handedness never enters: the camera vectors are given explicitly (no look_at) and
// every transformation is an explicit matrix.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "model/scene.hpp"
#include "vision/camera.hpp"
#include "vision/chessboard_render.hpp"

namespace uphill {

// The table's cover: wood and cloth as above; paper (a matte off-white sheet with a faint fibre
// mottle) and tiles (glazed ceramic squares of 100 mm with dark grout, satin, no mirror image).
enum class TableCover { kWood, kCloth, kPaper, kTiles };

// The body's finish: satin paint (the default: a soft highlight and a faint reflection), matte
// paint, glossy lacquer (a sharp highlight, 15 % reflection) or chrome (a mirror: it shows the
// room, its own colour hardly at all).
enum class BodyFinish { kSatin, kMatte, kGlossy, kChrome };

// A pattern in band_rgb over body_rgb, fixed to the body (it turns with it), in addition to the
// band: two-tone (one half of the body each side of a plane through its centre), stripes
// (parallel stripes of period pattern_scale) or dots (round spots of about pattern_scale).
// pattern_turn turns the pattern in the body's frame (POV-Ray `rotate`, degrees about x, y, z).
enum class BodyPattern { kPlain, kTwoTone, kStripes, kDots };

// A shadowless lamp (a room's light that adds highlights and shading, but no shadow the renderer
// would have to follow): apparatus frame, m; intensity as the scene's light scale.
struct FootageLamp {
  Eigen::Vector3d position;
  double intensity = 0.3;
};

// What the apparatus and the room look like (linear reflectances, 0..1, in R, G, B order).
struct FootageLook {
  TableCover table = TableCover::kWood;
  Eigen::Vector3d body_rgb{0.03, 0.06, 0.40};   // a dark blue ball
  Eigen::Vector3d band_rgb{0.02, 0.02, 0.02};
  double band_half_width = 0;                   // m; 0: a plain body
  double light = 1;                             // scale of all lights
  BodyFinish finish = BodyFinish::kSatin;
  BodyPattern pattern = BodyPattern::kPlain;
  double pattern_scale = 0;                     // m: stripe period, dot size
  Eigen::Vector3d pattern_turn{0, 0, 0};        // degrees
  std::optional<Eigen::Vector3d> rod_rgb;       // painted rods; unset: polished steel
  std::vector<FootageLamp> lamps;               // besides the soft box and the fill
};

// The drawn apparatus beyond the Scene's rails and body.
struct FootageApparatus {
  double crossbar_x = 1.0;          // horizontal distance O -> crossbar, m (L)
  double crossbar_radius = 0.008;   // m
  double post_radius = 0.009;       // m
  double rail_overhang = 0.03;      // rods continue this far (in x) beyond the crossbar, m
  double table_z = 0.0;             // m: the rails meet on the table
  double wall_y = 0.45;             // m
  std::vector<double> marks = {0.3, 0.6, 0.9};  // tape marks on both rails at these x, m
};

// The body's state in a rendered picture.
struct BodyPose {
  double x = 0, z = 0;  // centre, m (y = 0)
  double angle = 0;     // rotation about +y since release, rad
};

// A chessboard target in view: board frame as in chessboard_render.hpp (origin at the first inner
// corner, x along a row, y along a column), `pose` maps board points into the camera frame.
struct BoardInView {
  ChessboardTarget target;
  CameraPose pose;
  double margin_squares = 1;
};

// One POV-Ray run: the camera (pinhole: `camera.distortion` must be empty), the window of its
// image to render, and one picture per animation frame: the body at each pose (nullopt: no body)
// or a board.
struct PovrayShot {
  SceneCalibration camera;
  cv::Rect crop;
  std::vector<std::optional<BodyPose>> bodies;  // one animation frame each (≥ 1)
  // Optional, one per frame: frame k renders the window of crop's size at this corner instead.
  std::vector<cv::Point> crop_offsets;
  std::optional<BoardInView> board;             // the same board in every frame
};

// The SDL `camera { ... }` block of a shot (the pixel convention above), in millimetres.
std::string PovrayCameraText(const PovrayShot& shot);

// The SDL text. Throws InputError for a double cone (not drawn), rails without a rod radius
// (draw thin rails as rods of their real diameter), a camera with distortion, an empty crop or
// no frames.
std::string PovraySceneText(const Scene& scene, const FootageApparatus& apparatus, const FootageLook& look,
                            const PovrayShot& shot);

// The light reaching the table, as the scene sets it: the soft box's centre and its half size
// (apparatus frame, m), so that a renderer can bound the body's shadow.
struct SoftBox {
  Eigen::Vector3d centre;
  double half_size;
};
SoftBox FootageSoftBox(const FootageApparatus& apparatus);

// A chessboard view for the camera calibration: the board of `shot.board` (required) held in front
// of a grey backdrop, lit by a lamp above the camera; the camera's pose is taken as the frame of
// the scene (the board's pose is relative to the camera anyway). Throws InputError as above.
std::string PovrayBoardSceneText(const PovrayShot& shot);

}  // namespace uphill
