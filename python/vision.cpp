// Track CSVs (vision/track_table.hpp), camera and scene calibration files (vision/camera.hpp) and
// uphill.track: the ball's centre in every frame of a video, the use case of `uphill track`
// (app/track_video_file.hpp).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>

#include "app/track_video_file.hpp"
#include "bindings.hpp"
#include "vision/camera.hpp"
#include "vision/track_table.hpp"

namespace uphill::python {
namespace {

py::dict CameraToPython(const CameraIntrinsics& c) {
  py::dict d;
  d["width"] = c.width, d["height"] = c.height;
  d["fx"] = c.fx, d["fy"] = c.fy, d["cx"] = c.cx, d["cy"] = c.cy;
  d["distortion"] = c.distortion;
  return d;
}

// Columns of a track: one element per frame; a frame without the ball has found = False and NaN
// in u, v, radius_px, x, z, u_px, u_x, u_outline_px (never interpolated), quality 0. u_px, u_x are
// NaN too where the track states no uncertainty, u_outline_px where it states no outline spread.
struct TrackColumns {
  py::array_t<std::int64_t> frame;
  py::array_t<bool> found;
  py::array_t<double> t, u, v, radius_px, x, z, quality, u_px, u_x, u_outline_px;
  explicit TrackColumns(std::size_t n)
      : frame(Size(n)), found(Size(n)), t(Size(n)), u(Size(n)), v(Size(n)), radius_px(Size(n)), x(Size(n)),
        z(Size(n)), quality(Size(n)), u_px(Size(n)), u_x(Size(n)), u_outline_px(Size(n)) {}
  static py::ssize_t Size(std::size_t n) { return static_cast<py::ssize_t>(n); }
  void Set(std::size_t i, const TrackFrame& f) {
    const double missing = std::nan("");
    const auto found_only = [&](double value) { return f.found ? value : missing; };
    const bool stated = f.found && (f.u_px > 0 || f.u_x > 0);
    frame.mutable_at(i) = f.frame;
    found.mutable_at(i) = f.found;
    t.mutable_at(i) = f.t;
    u.mutable_at(i) = found_only(f.u);
    v.mutable_at(i) = found_only(f.v);
    radius_px.mutable_at(i) = found_only(f.radius_px);
    x.mutable_at(i) = found_only(f.x);
    z.mutable_at(i) = found_only(f.z);
    quality.mutable_at(i) = f.found ? f.quality : 0.0;
    u_px.mutable_at(i) = stated ? f.u_px : missing;
    u_x.mutable_at(i) = stated ? f.u_x : missing;
    u_outline_px.mutable_at(i) = f.found && f.u_outline_px > 0 ? f.u_outline_px : missing;
  }
  py::dict ToDict() const {
    py::dict d;
    d["frame"] = frame, d["t"] = t, d["found"] = found, d["u"] = u, d["v"] = v, d["radius_px"] = radius_px;
    d["x"] = x, d["z"] = z, d["quality"] = quality, d["u_px"] = u_px, d["u_x"] = u_x;
    d["u_outline_px"] = u_outline_px;
    return d;
  }
};

constexpr const char* kTrackColumnsDoc =
    "frame (int), t (s), found (bool), u, v (raw pixels), radius_px, x, z (m, apparatus frame), quality "
    "(0..1), u_px (raw pixels, each image axis) and u_x (m, along the rails): the standard uncertainty of the "
    "centre (NaN where the track states none), u_outline_px (raw pixels): the part of it that the frame's outline "
    "shows, its centre's spread over the outline's sectors (NaN where not stated); a frame without the ball keeps its element with found = False, "
    "NaN positions and quality 0 (never interpolated)";

}  // namespace

void BindVision(py::module_& m) {
  m.def(
      "read_track",
      [](const std::string& path) {
        const Track track = ReadTrackFile(path);
        TrackColumns c(track.frames.size());
        for (std::size_t i = 0; i < track.frames.size(); ++i) {
          c.Set(i, track.frames[i]);
        }
        return c.ToDict();
      },
      py::arg("path"),
      (std::string("Reads a track CSV as `uphill track` writes it (vision/track_table.hpp): dict of arrays ") +
       kTrackColumnsDoc + ". InputError names the file, row and column of the first bad row.")
          .c_str());

  m.def(
      "read_camera", [](const std::string& path) { return CameraToPython(ReadCameraFile(path)); }, py::arg("path"),
      "Reads a camera file (uphill-camera/1, calibration/README.md): dict of width, height (px), fx, fy, cx, cy "
      "(px) and the distortion coefficients (OpenCV's order).");
  m.def(
      "read_scene_calibration",
      [](const std::string& path) {
        const SceneCalibration s = ReadSceneFile(path);
        py::dict d;
        d["camera"] = CameraToPython(s.camera);
        d["rotation"] = Eigen::Matrix3d(s.pose.rotation);
        d["translation"] = Eigen::Vector3d(s.pose.translation);
        d["camera_centre"] = Eigen::Vector3d(CameraCentre(s.pose));
        return d;
      },
      py::arg("path"),
      "Reads a scene file (uphill-scene/1): the camera's intrinsics and its pose in the apparatus frame: "
      "rotation (3x3, apparatus -> camera), translation (m), camera_centre (m, apparatus frame).");

  m.def(
      "track",
      [](const std::string& video, const std::string& camera_file, const std::string& scene_file, const Scene& scene,
         const py::object& init_uv, const py::object& exposure, const py::object& readout, const std::string& transfer,
         const std::string& overlay) {
        TrackVideoFileOptions options;
        options.overlay_path = overlay;
        if (!init_uv.is_none()) {
          const auto uv = init_uv.cast<std::vector<double>>();
          if (uv.size() != 2 || !std::isfinite(uv[0]) || !std::isfinite(uv[1]))
            throw InputError("init_uv", "must be (u, v), two finite raw pixel coordinates");
          options.init_uv = Eigen::Vector2d(uv[0], uv[1]);
        }
        options.exposure = OptionalQuantity(exposure, Dimension::kTime, "exposure");
        if (py::isinstance<py::str>(readout) && readout.cast<std::string>() == "auto") options.measure_readout = true;
        else if (!readout.is_none()) options.readout = Quantity(readout, Dimension::kTime, "readout");
        options.transfer = ParseVideoTransfer(transfer, "transfer");
        TrackResult result;
        {
          py::gil_scoped_release release;
          result = TrackVideoFile(video, camera_file, scene_file, scene, options);
        }
        TrackColumns c(result.rows.size());
        for (std::size_t i = 0; i < result.rows.size(); ++i) {
          const TrackRow& r = result.rows[i];
          TrackFrame f;
          f.frame = r.frame, f.t = r.t, f.found = r.ball.found, f.quality = r.ball.quality;
          f.u = r.ball.u, f.v = r.ball.v, f.radius_px = r.ball.radius_px, f.x = r.ball.x, f.z = r.ball.z;
          f.u_px = r.u_px, f.u_x = r.u_x, f.u_outline_px = r.ball.outline_spread_px;
          c.Set(i, f);
        }
        py::dict d = c.ToDict();
        d["fps"] = result.fps;
        d["partial"] = result.partial;
        d["partial_reason"] = result.partial_reason;
        const auto seconds = [](const std::optional<double>& s) { return s ? py::object(py::float_(*s)) : py::none(); };
        d["exposure"] = seconds(result.exposure);
        d["measured_exposure"] = seconds(result.measured_exposure);
        d["readout"] = result.readout;
        return d;
      },
      py::arg("video"), py::arg("camera_file"), py::arg("scene_file"), py::arg("scene"), py::kw_only(),
      py::arg("init_uv") = py::none(), py::arg("exposure") = py::none(), py::arg("readout") = py::none(),
      py::arg("transfer") = "srgb", py::arg("overlay") = "",
      (std::string("The ball's centre in every frame of a video as `uphill track` finds it (app/track_video_file.hpp): "
                   "video any file FFmpeg decodes, camera_file the camera of `uphill calibrate camera`, scene_file "
                   "the scene calibration of `uphill calibrate scene` made with that camera (checked), scene the "
                   "uphill.Scene filmed (sphere or spheroid). init_uv=(u, v): a raw pixel near the centre in the "
                   "first frame; exposure: per frame (s, or text with a unit; None: measured from the motion blur); "
                   "readout: the rolling shutter's first-to-last-row time (s, or text), \"auto\" to measure it, "
                   "None for a global shutter; transfer: \"srgb\" (cameras) or \"linear\"; overlay: a video to "
                   "write with the fit drawn. Returns a dict of arrays ") +
       kTrackColumnsDoc + ", plus fps, partial and partial_reason (a cut video, a ball lost for good), exposure "
       "and measured_exposure (s, None when not known) and readout (s, as used).")
          .c_str());
}

}  // namespace uphill::python
