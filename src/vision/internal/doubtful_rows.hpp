// Internal to src/vision: the track's last look at its positions of a poor fit
// (TrackerOptions::min_report_quality), once every revision has been applied.
//
// A position whose quality is below the threshold is doubted: on random ray-traced scenes four
// in twenty of them were a pixel or more off, but most were right (a striped ball at rest,
// within 0.4 px at a quality of 0.38–0.45), so quality alone does not tell them apart. What
// does is the motion: a doubted position is left out where it lies more than
// kDoubtfulOffMotionPx from where the positions found in the kDoubtfulAroundFrames frames either
// side of it put the body at its time (internal::MotionFit through them, in raw pixels: over
// nine frames perspective bends the image path far less than that). The farthest is left out
// first and its doubted neighbours are judged again without it, since one position found wrong
// moves the motion its neighbours are judged by. A doubted position with fewer than three
// positions around it stays: nothing contradicts it. Nor is a print that holds the fit a pixel
// off over many frames told this way: its neighbours are as far off.
#pragma once

#include <vector>

#include "vision/video_tracking.hpp"

namespace uphill::internal {

// Three times the spread, px, of the difference between a position found right and the motion
// through its neighbours (a position's u_px, about 0.13 px, and the fit's, about 0.1 px).
inline constexpr double kDoubtfulOffMotionPx = 0.5;
// The frames either side whose positions make the motion (a parabola: over nine frames the
// acceleration changes little).
inline constexpr int kDoubtfulAroundFrames = 4;

// Leaves out (the row kept, its ball not found) each doubted row that lies off the motion around
// it; rows are in frame order, with their final times. Returns how many it left out.
long LeaveOutDoubtfulRows(double min_quality, std::vector<TrackRow>* rows);

}  // namespace uphill::internal
