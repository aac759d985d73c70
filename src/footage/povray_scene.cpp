#include "footage/povray_scene.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "model/input_error.hpp"

namespace uphill {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kMm = 1000.0;  // POV-Ray units per metre

std::string Num(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

std::string Vec(const Vector3d& v) { return "<" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + ">"; }

std::string Rgb(const Eigen::Vector3d& c) { return "rgb " + Vec(c); }

// POV-Ray's `matrix` keyword: a point p (row vector) goes to p·M + t, so the 3×3 block is the
// transpose of the column-vector matrix A of p ↦ A·p + t.
std::string PovMatrix(const Matrix3d& a, const Vector3d& t) {
  std::string s = "matrix <";
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) s += Num(a(col, row)) + ", ";
  return s + Num(t.x()) + ", " + Num(t.y()) + ", " + Num(t.z()) + ">";
}

// The camera; with per-frame windows, one camera per animation frame.
void AppendCamera(std::ostringstream& out, const PovrayShot& shot) {
  PovrayShot one = shot;
  one.crop_offsets.clear();
  if (shot.crop_offsets.size() <= 1) {  // a single picture is no animation: no frame_number
    if (!shot.crop_offsets.empty()) one.crop = cv::Rect(shot.crop_offsets[0], shot.crop.size());
    out << PovrayCameraText(one);
    return;
  }
  out << "#switch (frame_number)\n";
  for (size_t k = 0; k < shot.crop_offsets.size(); ++k) {
    one.crop = cv::Rect(shot.crop_offsets[k], shot.crop.size());
    out << "#case (" << k + 1 << ")\n" << PovrayCameraText(one) << "#break\n";
  }
  out << "#end\n";
}

}  // namespace

std::string PovrayCameraText(const PovrayShot& shot) {
  std::ostringstream out;
  const CameraIntrinsics& k = shot.camera.camera;
  const Matrix3d& r = shot.camera.pose.rotation;
  const Vector3d X = r.row(0).transpose(), Y = r.row(1).transpose(), Z = r.row(2).transpose();
  const Vector3d eye = CameraCentre(shot.camera.pose) * kMm;
  const double w = shot.crop.width, h = shot.crop.height;
  const Vector3d right = (w / k.fx) * X;
  const Vector3d up = -(h / k.fy) * Y;
  const Vector3d direction =
      Z + ((shot.crop.x + w / 2 - 0.5 - k.cx) / k.fx) * X + ((shot.crop.y + h / 2 - 0.5 - k.cy) / k.fy) * Y;
  out << "camera { perspective location " << Vec(eye) << "\n  right " << Vec(right) << " up " << Vec(up)
      << "\n  direction " << Vec(direction) << " }\n";
  return out.str();
}

namespace {

void AppendLights(std::ostringstream& out, const FootageApparatus& apparatus, const FootageLook& look,
                  const PovrayShot& shot) {
  const SoftBox box = FootageSoftBox(apparatus);
  const double side = 2 * box.half_size * kMm;
  // The soft box: a horizontal square of 9 × 9 point lights (adaptive sampling, no jitter, so
  // that a crop render matches the full render pixel for pixel), centred over its centre.
  out << "light_source { " << Vec(box.centre * kMm) << " color rgb " << Num(0.95 * look.light)
      << "\n  area_light <" << Num(side) << ", 0, 0>, <0, " << Num(side) << ", 0>, 9, 9 adaptive 1 }\n";
  // Fill light from the camera's side: lifts the shadows as the room's light does.
  const Vector3d fill = CameraCentre(shot.camera.pose) + Vector3d(0, -0.3, 0.6);
  out << "light_source { " << Vec(fill * kMm) << " color rgb " << Num(0.28 * look.light) << " shadowless }\n";
  for (const FootageLamp& lamp : look.lamps)
    out << "light_source { " << Vec(lamp.position * kMm) << " color rgb " << Num(lamp.intensity * look.light)
        << " shadowless }\n";
}

void AppendRoom(std::ostringstream& out, const FootageApparatus& apparatus, const FootageLook& look) {
  // The wall: matte paint with a faint mottle.
  out << "plane { <0, -1, 0>, " << Num(-apparatus.wall_y * kMm)
      << "\n  texture { pigment { bozo color_map { [0 rgb <0.50, 0.50, 0.47>] [1 rgb <0.56, 0.55, 0.52>] }"
         " scale 40 }\n    finish { diffuse 1 } } }\n";
  out << "plane { <0, 0, 1>, " << Num(apparatus.table_z * kMm) << "\n";
  if (look.table == TableCover::kWood) {
    // Flat-sawn oak: the rings of a trunk whose axis runs along x, 250 mm under the surface, with
    // turbulence; pores as fine dark noise; a satin varnish.
    out << "  texture {\n"
           "    pigment { wood turbulence 0.06 octaves 4 lambda 2.5\n"
           "      color_map { [0.00 rgb <0.52, 0.31, 0.14>] [0.35 rgb <0.58, 0.36, 0.17>]\n"
           "                  [0.70 rgb <0.42, 0.23, 0.09>] [1.00 rgb <0.52, 0.31, 0.14>] }\n"
           "      scale <7, 7, 300> translate <0, -250, 0> matrix <0, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0> }\n"
           "    normal { wood 0.15 turbulence 0.06 scale <7, 7, 300> translate <0, -250, 0>\n"
           "      matrix <0, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0> }\n"
           "    finish { diffuse 0.95 specular 0.15 roughness 0.03 reflection 0.02 } }\n"
           "  texture { pigment { granite color_map { [0 rgbt <0.2, 0.1, 0.05, 0.7>] [0.3 rgbt <0, 0, 0, 1>]"
           " [1 rgbt <0, 0, 0, 1>] }\n"
           "    scale <12, 1.2, 1.2> } finish { diffuse 0.95 } }\n";
  } else if (look.table == TableCover::kPaper) {
    // A sheet of matte off-white paper with a faint fibre mottle.
    out << "  texture { pigment { bozo color_map { [0 rgb <0.70, 0.69, 0.64>] [1 rgb <0.76, 0.75, 0.71>] }"
           " scale 3 }\n    finish { diffuse 0.95 } }\n";
  } else if (look.table == TableCover::kTiles) {
    // Glazed tiles of 100 mm with 3 mm dark grout, satin (no mirror image of the body).
    out << "  texture { pigment { gradient x color_map { [0 rgb 0.12] [0.03 rgb 0.12] [0.03 rgb <0.55, 0.52, 0.46>]"
           " [1 rgb <0.55, 0.52, 0.46>] } scale 100 }\n    finish { diffuse 0.85 specular 0.3 roughness 0.02 } }\n"
           "  texture { pigment { gradient y color_map { [0 rgbt <0.12, 0.12, 0.12, 0>] [0.03 rgbt <0.12, 0.12, 0.12, 0>]"
           " [0.03 rgbt 1] [1 rgbt 1] } scale 100 }\n    finish { diffuse 0.85 } }\n";
  } else {
    // A woven cloth: a soft grey-green gingham of 24 mm checks with a fibre texture, matte.
    out << "  texture {\n"
           "    pigment { average pigment_map {\n"
           "      [1 gradient x color_map { [0 rgb <0.36, 0.40, 0.33>] [0.42 rgb <0.36, 0.40, 0.33>]\n"
           "                                [0.50 rgb <0.22, 0.27, 0.20>] [0.92 rgb <0.22, 0.27, 0.20>]"
           " [1 rgb <0.36, 0.40, 0.33>] } scale 24 ]\n"
           "      [1 gradient y color_map { [0 rgb <0.36, 0.40, 0.33>] [0.42 rgb <0.36, 0.40, 0.33>]\n"
           "                                [0.50 rgb <0.22, 0.27, 0.20>] [0.92 rgb <0.22, 0.27, 0.20>]"
           " [1 rgb <0.36, 0.40, 0.33>] } scale 24 ] } }\n"
           "    normal { average normal_map { [1 gradient x 0.4 scale 1.1] [1 gradient y 0.4 scale 1.1]"
           " [1 bumps 0.5 scale 0.4] } }\n"
           "    finish { diffuse 0.9 } }\n";
  }
  out << "}\n";
}

void AppendApparatus(std::ostringstream& out, const Scene& scene, const FootageApparatus& apparatus,
                     const FootageLook& look) {
  const double T = scene.rails().tan_half_alpha, B = scene.rails().tan_theta;
  const double r = scene.rod_radius() * kMm;
  const double x_end = apparatus.crossbar_x + apparatus.rail_overhang;
  out << "#declare Steel = texture { pigment { rgb <0.60, 0.60, 0.62> }\n"
         "  finish { diffuse 0.3 specular 0.7 roughness 0.004 metallic brilliance 2"
         " reflection { 0.55 metallic } } }\n"
         "#declare Tape = texture { pigment { rgb 0.025 } finish { diffuse 1 specular 0.1 roughness 0.05 } }\n";
  if (look.rod_rgb)
    out << "#declare Rod = texture { pigment { " << Rgb(*look.rod_rgb)
        << " } finish { diffuse 0.9 specular 0.3 roughness 0.02 } }\n";
  else
    out << "#declare Rod = texture { Steel }\n";
  for (int side : {-1, 1}) {
    const Vector3d end(x_end, side * x_end * T, x_end * B);
    out << "cylinder { <0, 0, 0>, " << Vec(end * kMm) << ", " << Num(r) << " texture { Rod } }\n";
    const Vector3d e = end.normalized();
    for (double m : apparatus.marks) {
      if (m <= 0 || m >= apparatus.crossbar_x) continue;
      const Vector3d centre(m, side * m * T, m * B);
      const double half = 0.003 / e.x();  // a 6 mm wide tape (measured along x)
      out << "cylinder { " << Vec((centre - half * e) * kMm) << ", " << Vec((centre + half * e) * kMm) << ", "
          << Num(r * 1.08 + 0.02) << " texture { Tape } }\n";
    }
  }
  // The crossbar under the rails, and its two posts standing on the table under the rails.
  const double L = apparatus.crossbar_x;
  const double rc = apparatus.crossbar_radius;
  const double zc = L * B - scene.rod_radius() - rc;
  const double half = L * T + 0.05;
  out << "#declare Paint = texture { pigment { rgb <0.10, 0.13, 0.17> } finish { diffuse 0.9 specular 0.3"
         " roughness 0.02 } }\n";
  out << "cylinder { " << Vec(Vector3d(L, -half, zc) * kMm) << ", " << Vec(Vector3d(L, half, zc) * kMm) << ", "
      << Num(rc * kMm) << " texture { Paint } }\n";
  for (int side : {-1, 1}) {
    const Vector3d foot(L, side * L * T, apparatus.table_z);
    out << "cylinder { " << Vec(foot * kMm) << ", " << Vec(Vector3d(foot.x(), foot.y(), zc) * kMm) << ", "
        << Num(apparatus.post_radius * kMm) << " texture { Paint } }\n";
  }
}

std::string FinishText(BodyFinish finish) {
  switch (finish) {
    case BodyFinish::kMatte: return "finish { diffuse 0.95 }";
    case BodyFinish::kGlossy: return "finish { diffuse 0.8 specular 0.9 roughness 0.002 reflection 0.15 }";
    case BodyFinish::kChrome: return "finish { diffuse 0.04 specular 0.9 roughness 0.001 metallic reflection { 0.85 metallic } }";
    case BodyFinish::kSatin: break;
  }
  return "finish { diffuse 0.92 specular 0.35 roughness 0.012 reflection 0.035 }";
}

// The pattern as a second texture layer over the body's: band_rgb where the pattern is, clear
// elsewhere (in the unit sphere's frame, scaled with the body: lengths over a).
void AppendPattern(std::ostringstream& out, const FootageLook& look, double a_mm) {
  if (look.pattern == BodyPattern::kPlain) return;
  const std::string on = "rgbt <" + Num(look.band_rgb.x()) + ", " + Num(look.band_rgb.y()) + ", " +
                         Num(look.band_rgb.z()) + ", 0>";
  const double scale = std::max(1e-3, look.pattern_scale * kMm / a_mm);
  out << "  texture {\n    pigment { ";
  switch (look.pattern) {
    case BodyPattern::kTwoTone:
      out << "function { z > 0 } color_map { [0 rgbt 1] [0.5 rgbt 1] [0.5 " << on << "] [1 " << on << "] }";
      break;
    case BodyPattern::kStripes:
      out << "gradient z color_map { [0 " << on << "] [0.5 " << on << "] [0.5 rgbt 1] [1 rgbt 1] } scale "
          << Num(scale);
      break;
    case BodyPattern::kDots:
      out << "leopard color_map { [0 rgbt 1] [0.55 rgbt 1] [0.55 " << on << "] [1 " << on << "] } scale "
          << Num(scale / 3.14159265358979);
      break;
    case BodyPattern::kPlain: break;
  }
  out << "\n      rotate " << Vec(look.pattern_turn) << " }\n    " << FinishText(look.finish) << " }\n";
}

void AppendBody(std::ostringstream& out, const Scene& scene, const FootageLook& look, const BodyPose& pose) {
  const double a = scene.body().across * kMm, b = scene.body().along * kMm;
  const Matrix3d turn = Eigen::AngleAxisd(pose.angle, Vector3d::UnitY()).toRotationMatrix();
  out << "sphere { <0, 0, 0>, 1\n  texture {\n";
  if (look.band_half_width > 0) {
    // In the unit sphere's frame (the texture is scaled with the body): |z| < w/a is the band.
    const double edge = std::min(0.99, look.band_half_width * kMm / a);
    out << "    pigment { function { abs(z) } color_map { [0 " << Rgb(look.band_rgb) << "] [" << Num(edge) << " "
        << Rgb(look.band_rgb) << "] [" << Num(edge) << " " << Rgb(look.body_rgb) << "] [1 " << Rgb(look.body_rgb)
        << "] } }\n";
  } else {
    out << "    pigment { " << Rgb(look.body_rgb) << " }\n";
  }
  out << "    " << FinishText(look.finish) << " }\n";
  AppendPattern(out, look, a);
  out << "  scale <" << Num(a) << ", " << Num(b) << ", " << Num(a) << ">\n  "
      << PovMatrix(turn, Vector3d(pose.x, 0, pose.z) * kMm) << "\n}\n";
}

void AppendBoard(std::ostringstream& out, const PovrayShot& shot, const BoardInView& board) {
  // Board frame -> apparatus frame: p_app = Rᵀ·(R_b·p + t_b − t).
  const Matrix3d& r = shot.camera.pose.rotation;
  const Matrix3d a = r.transpose() * board.pose.rotation;
  const Vector3d o = r.transpose() * (board.pose.translation - shot.camera.pose.translation) * kMm;
  const double s = board.target.square * kMm, m = board.margin_squares * s;
  const double x1 = board.target.cols * s, y1 = board.target.rows * s;
  // The camera looks at the face z = 0 from z < 0 (the board's z axis points away from it).
  out << "union {\n  box { <" << Num(-s - m) << ", " << Num(-s - m) << ", 0>, <" << Num(x1 + m) << ", "
      << Num(y1 + m) << ", 3> texture { pigment { rgb 0.80 } finish { diffuse 1 } } }\n"
      << "  box { <" << Num(-s) << ", " << Num(-s) << ", -0.02>, <" << Num(x1) << ", " << Num(y1) << ", 1>\n"
      << "    texture { pigment { checker rgb 0.012 rgb 0.80 translate <0, 0, 0.5> scale <" << Num(s) << ", "
      << Num(s) << ", 1000> } finish { diffuse 1 } } }\n  " << PovMatrix(a, o) << "\n}\n";
}

void CheckShot(const PovrayShot& shot) {
  if (!shot.crop_offsets.empty() && shot.crop_offsets.size() != shot.bodies.size())
    throw InputError("crop offsets", "give one per frame, or none");
  if (!shot.camera.camera.distortion.empty())
    throw InputError("camera", "POV-Ray renders the pinhole camera; the lens distortion is applied afterwards");
  if (shot.crop.width <= 0 || shot.crop.height <= 0) throw InputError("crop", "must not be empty");
  if (shot.bodies.empty()) throw InputError("frames", "a POV-Ray shot needs at least one frame");
}

const char* kPreamble =
    "// uphill footage: the rolling-uphill apparatus (src/footage/povray_scene.hpp). Units: mm.\n"
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 max_trace_level 6 adc_bailout 0.002 }\n"
    "#default { finish { ambient 0 diffuse 1 } }\n";

}  // namespace

std::string PovrayBoardSceneText(const PovrayShot& shot) {
  CheckShot(shot);
  if (!shot.board) throw InputError("board", "a chessboard view needs a board");
  std::ostringstream out;
  out << kPreamble;
  AppendCamera(out, shot);
  // Camera frame: x right, y down, z forward (mm). A lamp above and behind the camera, a fill at it.
  out << "light_source { <250, -900, -500> color rgb 0.75 area_light <300, 0, 0>, <0, 0, 300>, 5, 5 adaptive 1 }\n"
         "light_source { <0, 0, 0> color rgb 0.25 shadowless }\n"
         "plane { <0, 0, -1>, -3000 texture { pigment { bozo color_map { [0 rgb 0.22] [1 rgb 0.30] } scale 80 }"
         " finish { diffuse 1 } } }\n";
  AppendBoard(out, shot, *shot.board);
  return out.str();
}

SoftBox FootageSoftBox(const FootageApparatus& apparatus) {
  // Above the apparatus, a little beyond its middle and behind it: the body's shadow falls on
  // the table beside it, toward O and the camera, where the camera sees it.
  return {Vector3d(0.45 * apparatus.crossbar_x + 0.35, 0.1, apparatus.table_z + 1.0), 0.25};
}

std::string PovraySceneText(const Scene& scene, const FootageApparatus& apparatus, const FootageLook& look,
                            const PovrayShot& shot) {
  if (scene.body().kind == BodyKind::kDoubleCone)
    throw InputError("body", "the POV-Ray footage draws a sphere or a spheroid, not a double cone");
  if (!(scene.rod_radius() > 0))
    throw InputError("rails", "the POV-Ray footage draws rails as round rods: give the rod (or wire) diameter");
  CheckShot(shot);
  std::ostringstream out;
  out << kPreamble;
  AppendCamera(out, shot);
  AppendLights(out, apparatus, look, shot);
  AppendRoom(out, apparatus, look);
  AppendApparatus(out, scene, apparatus, look);
  if (shot.board) AppendBoard(out, shot, *shot.board);
  // One body pose per animation frame (frame_number counts from 1; a single picture is no
  // animation and has its body, if any, unconditionally).
  if (shot.bodies.size() == 1) {
    if (shot.bodies[0]) AppendBody(out, scene, look, *shot.bodies[0]);
  } else {
    out << "#switch (frame_number)\n";
    for (size_t k = 0; k < shot.bodies.size(); ++k) {
      if (!shot.bodies[k]) continue;
      out << "#case (" << k + 1 << ")\n";
      AppendBody(out, scene, look, *shot.bodies[k]);
      out << "#break\n";
    }
    out << "#end\n";
  }
  return out.str();
}

}  // namespace uphill
