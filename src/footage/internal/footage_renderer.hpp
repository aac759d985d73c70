// FootageRenderer: draws one footage condition (footage_clip.hpp) with POV-Ray: the static
// scene once, each frame's moving parts as sub-frame renders of the regions the body and its
// shadow cover, composed over the static picture, and the chessboard views. Private to
// footage_clip.cpp; part of the footage generator, whose code is in the footage cache key.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "motion/motion.hpp"
#include "footage/footage_clip.hpp"
#include "footage/lens_remap.hpp"
#include "footage/povray_render.hpp"
#include "footage/povray_scene.hpp"
#include "footage/sensor_model.hpp"

namespace uphill::internal {

struct Cylinder {
  Eigen::Vector3d p0, e;
  double r, length;
};

struct PovrayWork {
  int subframes = 0;
  double pixels = 0;
  bool cached = false;
};

class FootageRenderer {
 public:
  // work: a private folder for POV-Ray's files; pictures: the shared cache of POV-Ray renders.
  FootageRenderer(const FootageCondition& c, const std::filesystem::path& work, const std::filesystem::path& pictures);

  const LensRemap& lens() const { return lens_; }

  int PoseIndex(int frame) const;
  double Exposure(int frame) const;
  double Gain(int frame) const;

  // The body at clip time t (nullopt: never visible, or the motion has ended).
  std::optional<BodyPose> BodyAt(double t) const;

  // Raw pixel box of the body with what it changes near itself: its mirror image in a wooden
  // table, its reflections in the rods (a margin of half its radius), its soft shadow on the
  // rods. Empty when off the frame.
  cv::Rect BodyBox(const BodyPose& p, int pose_index) const;

  // Raw pixel box of the body's soft shadow on the table (from every corner of the soft box).
  cv::Rect ShadowBox(const BodyPose& p, int pose_index) const;

  // Raw pixel of the centre of the body's shadow on the table (from the soft box's centre).
  Eigen::Vector2d ShadowCentre(const BodyPose& p, int pose_index) const;

  Eigen::Vector3d Corner(const BodyPose& p, int k) const;

  // Points of the rods that the body shades from part of the soft box (a conservative penumbra):
  // along each rod's axis (2 mm steps within 0.4 m of the body), those from which the body's
  // bounding sphere (grown by the rod's radius) hides some of the soft box. Seen from a rod point
  // q the sphere is a cone of half angle α about q → centre; it meets the lamp's plane in an
  // ellipse about the point Lc where q → centre does, inside the circle of radius
  // |Lc − q|·tan α / cos(θ + α) (θ the cone axis' angle from the vertical); the point is kept when
  // that circle meets the square. Sampling a few points of the soft box instead misses the far
  // penumbra, where the sphere hides a spot smaller than their spacing.
  void AddRodShadowPoints(const BodyPose& p, std::vector<Eigen::Vector3d>* points) const;

  // The body's bounding box projected from each corner of the soft box onto the plane z.
  void AddShadowPoints(const BodyPose& p, double z, std::vector<Eigen::Vector3d>* points) const;

  cv::Rect PixelBox(const std::vector<Eigen::Vector3d>& points, int pose_index, double margin) const;

  Eigen::Vector2d Project(const BodyPose& p, int pose_index) const;

  // Fraction of the body's silhouette inside the frame and not hidden by the apparatus.
  double Visibility(const BodyPose& p, int pose_index) const;

  // The static scene (no body) as a raw linear picture, for each camera pose.
  void RenderStatic();

  struct PovrayJob {
    PovrayShot shot;
    std::vector<cv::Mat> pictures;
  };

  // The whole pinhole picture without the body, for each camera pose.
  std::vector<PovrayJob> StaticJobs() const;

  // A part of the picture that the moving body changes, rendered at its own sub-frame times:
  // sub-frame k covers [i0 + k·dt, i0 + (k + 1)·dt] and renders the pinhole window around its own
  // raw box (a long blur would otherwise render the whole smear K times); the windows share one
  // size, so that one POV-Ray run renders several.
  struct Region {
    double i0 = 0, dt = 0;
    std::vector<std::optional<BodyPose>> bodies;  // per sub-frame
    std::vector<cv::Rect> boxes, windows;         // per sub-frame: its raw box, its pinhole window
    cv::Rect box;                                 // all sub-frames' boxes: the pixels composited
    std::vector<cv::Mat> raw;                     // per sub-frame: its raw box, once rendered
  };

  // What frame f needs: its truth, and the regions the body changes. Usually one region (the body
  // with its shadow). A body high above the table casts its soft shadow far from itself: then
  // the shadow on the table is a region of its own, sampled in time by its own, slower measure
  // (a penumbra of p px moving by p/6 px between sub-frames changes the picture as little as a
  // sharp edge moving by max_step_px), while the body's region keeps the body's fine steps.
  struct FramePlan {
    int frame = 0, pose_index = 0;
    double exposure = 0;
    ClipTruth truth;
    std::vector<Region> regions;  // disjoint boxes; empty: the static scene only
  };

  FramePlan Plan(int f) const;

  // K sub-frames over [i0, i1] with the windows of the body (and its nearby shadow and
  // reflections) and/or of its shadow on the table.
  Region MakeRegion(double i0, double i1, int K, int pi, bool body, bool shadow) const;

  // Renders the sub-frames of the plans, several POV-Ray processes at once (POV-Ray 3.7 idles
  // ~0.2 s per picture in its own polling loops, so one process at a time leaves the CPU idle).
  // A region of one sub-frame with the same pose and window as one already rendered (a body at
  // rest) is reused.
  void Render(std::vector<FramePlan>& plans);

  struct Part {
    Region* region;
    int pose_index;
    size_t first;  // its first sub-frame
  };
  struct Batch {
    std::vector<PovrayJob> jobs;
    std::vector<Part> parts;                         // per job: the sub-frames it renders
    std::vector<std::pair<Region*, size_t>> copies;  // regions that take a job's picture
  };

  // The POV-Ray jobs of the plans' sub-frames, `subframes` counted; a resting region rendered
  // before (rest_) takes its picture now, one rendered in this batch becomes a copy.
  Batch Jobs(std::vector<FramePlan>& plans);

  // The linear raw frame of a rendered plan (before vignetting, gain and noise): each row the
  // static scene times the light's mean over its window; each region's box Σ_k w_k·picture_k.
  cv::Mat Compose(const FramePlan& plan) const;

  // What POV-Ray would be asked for (its scene text and picture size) and whether the picture
  // cache holds it already.
  PovrayWork Work(const PovrayJob& job) const;

  // The chessboard views (camera frame as the scene's frame), rendered in parallel.
  std::vector<cv::Mat> RenderBoards(const std::vector<BoardInView>& boards);

  const cv::Mat& vignetting() const { return vignetting_; }
  int povray_runs = 0, povray_cached = 0, subframes = 0;
  double povray_cpu = 0;

 private:
  std::string Text(const PovrayJob& job) const;

  // Runs the jobs on up to povray_processes POV-Ray processes at once (`threads` each, at most
  // povray.threads).
  void RunJobs(std::vector<PovrayJob>& jobs, int threads);

  std::string RestKey(const Region& region, int pose_index) const;

  const FootageCondition& c_;
  std::filesystem::path work_, pictures_;
  LensRemap lens_;
  Motion motion_;
  ShutterTiming timing_;
  cv::Mat vignetting_;
  std::vector<Cylinder> occluders_;
  std::vector<CameraPose> poses_;
  std::vector<cv::Mat> static_raw_;
  double a_ = 0, b_ = 0;
  std::map<std::string, cv::Mat> rest_;
};

}  // namespace uphill::internal
