// Running POV-Ray: renders a scene text (povray_scene.hpp) with the `povray` program (Debian
// package `povray`, POV-Ray 3.7) and returns the pictures in linear light.
//
// How: the text is written to `work_dir/shot.pov` and POV-Ray runs there (its default I/O
// security lets it write only below the current directory and /tmp), with +FN16 and
// File_Gamma=1.0 (16-bit PNG, linear: the scene's assumed_gamma is 1.0, so a pixel value is the
// rendered radiance, clipped to [0, 1]), adaptive anti-aliasing without jitter (+AM2, +R, -J:
// deterministic, so that a small window re-rendered later matches the full picture), and one
// animation frame per picture (+KFI1 +KFF n; the scene switches on frame_number).
//
// Errors: EnvironmentError when povray is missing (naming the package); std::runtime_error when
// it fails (with the last lines of its log, which stays in work_dir/shot.log) or writes no picture.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace uphill {

struct PovrayOptions {
  // +A: supersample where neighbouring samples differ by more (linear light): the body's outline
  // and the rods' edges, not the grain of the table (~2 samples per pixel on average).
  double antialias_threshold = 0.06;
  int antialias_depth = 2;            // +R: up to (2^depth + 1)^2 = 25 samples per pixel
  int threads = 2;                    // +WT
  std::string program = "povray";
  // If set: a folder of earlier renders, keyed by the scene text, size, frame count and quality;
  // a render found there is read instead of run again (the same text renders the same pictures:
  // no jitter), a new one is added. Any part of it may be deleted at any time.
  std::string picture_cache;
};

struct PovrayRun {
  std::vector<cv::Mat> pictures;  // CV_32FC3, BGR, linear, one per frame, `size` each
  double wall_seconds = 0;
  double cpu_seconds = 0;         // CPU time of the povray process (all its threads); 0 if cached
  bool cached = false;            // read from PovrayOptions::picture_cache
};

// Throws std::invalid_argument for an empty size or frames < 1.
PovrayRun RunPovray(const std::string& scene_text, cv::Size size, int frames, const std::string& work_dir,
                    const PovrayOptions& options = {});

// True when options.picture_cache holds the pictures RunPovray would render for these arguments
// (then RunPovray reads them instead of running POV-Ray).
bool PovrayPicturesCached(const std::string& scene_text, cv::Size size, int frames, const PovrayOptions& options);

// True when the povray program can be run (for tests and benchmarks that need it).
bool PovrayAvailable(const std::string& program = "povray");

}  // namespace uphill
