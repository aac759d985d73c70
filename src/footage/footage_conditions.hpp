// The robustness matrix of the tracker: named conditions of the POV-Ray footage
// (footage_clip.hpp), each a short clip that differs from a baseline in one respect, plus the
// issue's two failing clips and three clips of bad input.
//
// Two apparatus ("families"):
//  lab   the default apparatus of the project (L = 1000 mm, H = 100 mm, D = 150 mm, horizontal L;
//        X = 314 mm for the 2-inch ball on 8 mm rods), a 2-inch (R = 25.4 mm) dark blue ball at rest
//        at x0 = 250 mm for 0.3 s, then rolling back toward O (0.5 m/s after 1.25 s), seen from the
//        side from 1.1 m (ball radius ~27 px at 720p); wood table. 1.5 s.
//  fast  steep rails (L = 1000 mm, H = 250 mm, D = 20 mm: θ = 14°, no equilibrium in reach), a
//        1-inch (R = 12.7 mm) ball released at x0 = 700 mm, 1.2 m/s after 0.73 s: a 360° shutter at
//        30 fps smears it over 3.1 radii; a woven cloth table, 1080p. 1.0 s.
// Camera of both: a phone's (fx = fy = 0.9·width, principal point a little off centre, barrel
// distortion k1 = −0.12, k2 = 0.06, p1 = 7e-4, p2 = −4e-4, k3 = −0.015, vignetting s = 0.5, a
// 4000-electron full well with 3 electrons read noise), H.264 at a phone's bit rate.
//
// The conditions (name: what differs from the family's baseline):
//   clean                lab 720p30, no noise, lossless FFV1, 1/500 s exposure (the ≤ 0.1 px goal)
//   baseline             lab 720p30, 180° shutter, noise, H.264
//   h265                 baseline in H.265
//   1080p                baseline at 1920 × 1080
//   isoluminant          the ball's colour has the wood's grey level (contrast in colour only)
//   cloth                a woven cloth table instead of wood
//   thin-rails           1 mm wires instead of 8 mm rods
//   spheroid-band        the paper's yellow spheroid (a = 15.875 mm, b = 25.4 mm) with a dark
//                        painted band through its rolling axis, on 1 mm wires, 720p60
//   flicker              mains flicker: 30 % modulation at 100 Hz
//   ae-drift             automatic exposure drifting ±15 % over 1.5 s
//   partly-out           the frame's left edge at x ≈ 190 mm: the ball rolls out of the picture
//   fast-180-30 … fast-360-60   fast family at 1080p, shutter 180°/360° at 30/60 fps
//   rolling-shutter      fast 1080p30 180°, rows read over 25 ms
//   bad-no-body          the apparatus without the body
//   bad-camera-moved     the camera is bumped at 0.9 s (0.6° turn, 4 mm shift)
//   bad-exposure-change  at 0.9 s the exposure drops from 1/60 s to 1/250 s and the gain jumps 1.6×
// `tiny` (not in the matrix): the lab baseline at 320 × 180, 10 frames, for the tests.
#pragma once

#include <string>
#include <vector>

#include "footage/footage_clip.hpp"

namespace uphill {

// What the benchmark expects of a condition: a track to score, or bad input to be reported.
enum class FootageExpectation { kTrack, kBadInput };

struct NamedFootage {
  FootageCondition condition;
  FootageExpectation expectation = FootageExpectation::kTrack;
  std::string description;  // one line, for tables
};

// The matrix, in the order above.
std::vector<NamedFootage> RobustnessMatrix();

// One condition by name (the matrix's, or "tiny"). Throws InputError listing the names.
NamedFootage FootageByName(const std::string& name);

// The body flags of `uphill track` and `uphill analyse-track` for a condition
// ("--body sphere --R 25.4mm --L 1000mm --H 100mm --D 150mm --rod-diameter 8mm").
std::string FootageSceneFlags(const FootageCondition& condition);

}  // namespace uphill
